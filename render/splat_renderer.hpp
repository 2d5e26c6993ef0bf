// The splat renderer of a render model in memory (render_model.hpp): its
// tiles culled and thinned by the frame plan (frame_plan.hpp), drawn by the
// splat passes (splat_passes.hpp).
//
// Needs the device's context current for its whole life.
#pragma once

#include <memory>

#include "render/frame_plan.hpp"
#include "render/render_model.hpp"
#include "render/render_view.hpp"
#include "render/splat_passes.hpp"

namespace scanbench::render {

struct FrameResult {
  FramePlan plan;
  double frame_ms = 0.0;  // CPU wall time of the frame, finished on the device
  // The device's own time for the frame's commands (a GL_TIME_ELAPSED
  // query); negative where the device cannot say.
  double gpu_ms = -1.0;
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

  // The last frame on the device (splat_passes.hpp). Asserts that a frame
  // was drawn.
  using PictureTexture = render::PictureTexture;
  PictureTexture picture_texture() const;

 private:
  struct Gpu;
  const RenderModel& model_;
  std::unique_ptr<Gpu> gpu_;
  Eigen::Vector2f height_range_;  // of the model's points [m, model frame z]
};

}  // namespace scanbench::render
