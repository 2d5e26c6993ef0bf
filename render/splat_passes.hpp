// The passes of a splat frame (seed 004 §5, its Fig. 3), whatever feeds
// them points: every point a disk of its own world-space radius (the
// footprint), drawn as a point sprite whose fragments intersect the view
// ray with the disk, so a splat oriented by its normal is an ellipse in
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
// A renderer gives the vertex stage that reads its points (splat_shaders.hpp)
// and a callback that issues its draws; SplatPasses owns the programs, the
// frame's targets and the picture. Needs the device's context current for
// its whole life.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "render/clipping.hpp"
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

// An RGBA8 picture, top row first; alpha 0 where nothing was drawn.
struct RenderedImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;

  bool covered(int x, int y) const {
    return rgba[4 * (static_cast<std::size_t>(y) * width + x) + 3] != 0;
  }
  // The picture without alpha: RGB, 3 bytes a pixel, top row first.
  std::vector<std::uint8_t> rgb() const;
  // 1 where something was drawn, a byte a pixel.
  std::vector<std::uint8_t> coverage() const;
};

// The last frame on the device, for a window to show without reading it
// back: the OpenGL name of its RGBA8 texture (bottom row first) and the
// picture's rectangle in it as texture coordinates (u0, v0, u1, v1).
struct PictureTexture {
  unsigned texture = 0;
  std::array<float, 4> uv{};
};

class SplatPasses {
 public:
  // The band beyond each edge of the picture where a splat's centre may
  // lie and its splat still be drawn (render_view.hpp): half the widest
  // sprite GL draws (255 pixels), so no splat that reaches into the
  // picture is dropped. The targets are the picture's size: the view's
  // viewport overhangs them by the band.
  static constexpr int kGuardBandPixels = 128;

  // Builds the programs: `vertex_source` is a splat vertex stage
  // (splat_shaders.hpp).
  explicit SplatPasses(const std::string& vertex_source);
  ~SplatPasses();
  SplatPasses(const SplatPasses&) = delete;
  SplatPasses& operator=(const SplatPasses&) = delete;

  // The view a frame of `picture_view` is drawn through: the picture and
  // its guard band.
  static RenderView banded(const RenderView& picture_view);

  // Draws a frame through `banded_view` (banded(picture view)): the
  // frame's uniforms, then the passes of `settings.mode`, each calling
  // `draw_points` to issue the renderer's draws with the splat program
  // bound, then the resolve. `height_range` spans the model's heights (the
  // height colour mode). Leaves the context's GL state as it found it
  // (gl_state.hpp). Returns the device's time for the frame [ms], negative
  // where the device cannot say.
  double draw(const RenderView& banded_view, const RenderSettings& settings,
              const Eigen::Vector2f& height_range, const std::function<void()>& draw_points);

  // Sets a uniform of the splat program (a renderer's own, per draw).
  void uniform(const char* name, int value) const;
  void uniform(const char* name, unsigned value) const;
  void uniform(const char* name, float value) const;
  void uniform(const char* name, const Eigen::Vector3f& value) const;

  // The last frame, without its guard band. Assert that a frame was drawn.
  RenderedImage read_image() const;
  PictureTexture picture_texture() const;

 private:
  struct Gpu;
  std::unique_ptr<Gpu> gpu_;
  int picture_width_ = 0;
  int picture_height_ = 0;
};

}  // namespace scanbench::render
