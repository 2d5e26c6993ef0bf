// The splat renderer (seed 004 §5, its Fig. 3): every point a disk of its own
// world-space radius (the footprint; the seed's hardware could only give one
// size per object), drawn as a point sprite whose fragments intersect the
// view ray with the disk, so a splat oriented by its normal is an ellipse in
// true perspective, with its true depth.
//
// Modes:
//   points   every point one pixel: the raw scan, holes and all;
//   splats   opaque disks, the nearest wins;
//   blended  two passes and a resolve: a visibility pass writes the depth of
//            the nearest splats pushed back by depth_offset × their radius; an
//            accumulation pass adds kernel weight × colour and the weight of
//            every splat within that depth into a float target (no depth
//            writes); the resolve divides. Overlapping splats of one surface
//            blend; a surface behind them does not.
//
// Needs the device's context current for its whole life.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "render/frame_plan.hpp"
#include "render/render_model.hpp"
#include "render/render_view.hpp"

namespace scanbench::render {

enum class DrawMode { kPoints, kSplats, kBlended };
enum class Kernel { kDisk, kGaussian, kCosine };
enum class ColorMode { kColor, kIntensity, kHeight, kNormal, kObject };

std::string_view draw_mode_name(DrawMode mode);
std::string_view kernel_name(Kernel kernel);
std::string_view color_mode_name(ColorMode mode);
std::optional<DrawMode> draw_mode_from_name(std::string_view name);
std::optional<Kernel> kernel_from_name(std::string_view name);
std::optional<ColorMode> color_mode_from_name(std::string_view name);

struct RenderSettings {
  DrawMode mode = DrawMode::kBlended;
  Kernel kernel = Kernel::kGaussian;
  ColorMode color = ColorMode::kColor;
  bool oriented = true;  // disks in the plane of their normal (else facing the camera)
  // × the splat radii. A sample's cell is covered by exactly its half
  // diagonal on an ideal grid; 1.5 overlaps the neighbours, which closes the
  // gaps noise and the merge leave and gives blending something to blend.
  float splat_scale = 1.5f;
  float depth_offset = 1.0f;  // blended: the visibility pass's push back, × the splat radius
  bool lighting = false;      // diffuse shading from the normals, light at the eye
  bool eye_dome = false;      // eye-dome lighting: depth edges darkened (scans without colour)
  // Splats and blended: a pixel nothing landed on but with splats of one
  // surface in all 8 directions within this many pixels takes their colour
  // (0: off). Points mode never fills: it shows the raw samples.
  int fill_reach_px = 3;
  std::array<std::uint8_t, 3> background = {0, 0, 0};  // sRGB
  CullSettings culling;
};

struct FrameResult {
  FramePlan plan;
  double frame_ms = 0.0;  // CPU wall time of the frame, finished on the device
  // The device's own time for the frame's commands (a GL_TIME_ELAPSED
  // query); negative where the device cannot say.
  double gpu_ms = -1.0;
};

// An RGBA8 picture, top row first; alpha 0 where nothing was drawn.
struct RenderedImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;

  bool covered(int x, int y) const {
    return rgba[4 * (static_cast<std::size_t>(y) * width + x) + 3] != 0;
  }
};

class SplatRenderer {
 public:
  // Uploads the model's points. The model must outlive the renderer (its
  // tiles and tree are read every frame).
  explicit SplatRenderer(const RenderModel& model);
  ~SplatRenderer();
  SplatRenderer(const SplatRenderer&) = delete;
  SplatRenderer& operator=(const SplatRenderer&) = delete;

  // Draws a frame into the offscreen target (the view's size and a guard
  // band round it). Leaves the context's GL state as it found it
  // (gl_state.hpp), so a caller drawing more (the workbench's UI) needs no
  // repair.
  FrameResult draw(const RenderView& view, const RenderSettings& settings);

  // The last frame, without its guard band. Asserts that a frame was drawn.
  RenderedImage read_image() const;

  // The last frame on the device, for a window to show without reading it
  // back: the OpenGL name of its RGBA8 texture (bottom row first) and the
  // picture's rectangle in it, without the guard band, as texture
  // coordinates (u0, v0, u1, v1). Asserts that a frame was drawn.
  struct PictureTexture {
    unsigned texture = 0;
    std::array<float, 4> uv{};
  };
  PictureTexture picture_texture() const;

 private:
  // Pixels drawn beyond each edge of the picture (render_view.hpp): half
  // the widest sprite GL draws (255 pixels), so no splat that reaches into
  // the picture is dropped.
  static constexpr int kGuardBandPixels = 128;

  struct Gpu;
  const RenderModel& model_;
  std::unique_ptr<Gpu> gpu_;
  int picture_width_ = 0;
  int picture_height_ = 0;
  Eigen::Vector2f height_range_;  // of the model's points [m, model frame z]
};

}  // namespace scanbench::render
