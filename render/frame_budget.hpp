// The point budget that keeps frames near a target time while the camera
// moves (seed 000 §4 draws a fixed budget of points a frame; here it follows
// what this device manages): after each moving frame the budget is scaled
// by the target over the time the frame took, at most halved or grown by
// half at once, so a frame that ran long is followed by a cheaper one
// within a frame or two. A still camera has no budget: the picture refines
// to full quality.
#pragma once

#include <cstddef>

namespace scanbench::render {

class FrameBudget {
 public:
  static constexpr std::size_t kFewestPoints = 20000;  // a picture still worth a look

  // `target_ms` > 0.
  explicit FrameBudget(double target_ms, std::size_t first_budget = 250000);

  // The next frame's point budget; 0 (none) when the camera is still.
  std::size_t next(bool moving) const { return moving ? budget_ : 0; }

  // A moving frame drew `points` in `frame_ms`. A frame that drew fewer
  // points than its budget (the view needed no more) lets the budget grow
  // only to twice what it drew.
  void record(double frame_ms, std::size_t points);

  double target_ms() const { return target_ms_; }

 private:
  double target_ms_;
  std::size_t budget_;
};

}  // namespace scanbench::render
