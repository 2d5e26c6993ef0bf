// The point budget that keeps frames within a target time while the camera
// moves (seed 000 §4 draws a fixed budget of points a frame; here it follows
// what this device manages): after each moving frame the budget is scaled
// by 85 % of the target over the time the frame took, at most halved or
// grown by half at once, so a frame that ran long is followed by a cheaper one
// within a frame or two. A still camera has no budget: the picture refines
// to full quality.
//
// Points are not all a frame costs: fewer points draw larger splats, and a
// device without a GPU (llvmpipe) spends most of a frame filling them. So
// when the budget is down to its fewest points and frames still run long,
// moving frames are drawn smaller (fewer pixels, scaled up on screen),
// down to kSmallestScale of the picture's width and height; faster frames
// give the resolution back first, then the points.
#pragma once

#include <cstddef>

#include "acquisition/camera_view.hpp"

namespace scanbench::render {

class FrameBudget {
 public:
  static constexpr std::size_t kFewestPoints = 20000;  // a picture still worth a look

  // `target_ms` > 0.
  explicit FrameBudget(double target_ms, std::size_t first_budget = 250000);

  static constexpr double kSmallestScale = 0.375;
  // The share of the target frames aim at, so that most meet it: a frame's
  // time varies from one to the next with what it draws.
  static constexpr double kAim = 0.85;

  // The next frame's point budget; 0 (none) when the camera is still.
  std::size_t next(bool moving) const { return moving ? budget_ : 0; }
  // The next frame's size as a share of the picture's width and height, in
  // steps of 1/16 (a new size reallocates the device's targets); 1 when
  // the camera is still.
  double scale(bool moving) const;

  // A moving frame drew `points` in `frame_ms`. A frame that drew fewer
  // points than its budget (the view needed no more) lets the budget grow
  // only to twice what it drew.
  void record(double frame_ms, std::size_t points);

  double target_ms() const { return target_ms_; }

 private:
  double target_ms_;
  std::size_t budget_;
  double scale_ = 1.0;
};

// `camera` drawn `scale` times as wide and high (at least 16 × 16 pixels),
// the same view.
acquisition::CameraView at_scale(const acquisition::CameraView& camera, double scale);

}  // namespace scanbench::render
