// Scripted user sessions for bench "segmentation" (issue #13): for a
// ground-truth object, the clicks, lasso and barrier a user looking at the
// panorama would make, played through our region grower.
//
// What the script knows of the truth is what the user's eyes know: where the
// object is in the image (to click inside it, to draw a lasso around it with
// a margin, to draw a barrier under a post's foot, and to click again where
// the region visibly fell short). The grower itself never sees the truth.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "segmentation/pixel_set.hpp"
#include "segmentation/region_grow.hpp"

namespace scanbench::bench {

// An object of the truth as the scan saw it.
struct TargetObject {
  std::uint16_t id = 0;
  std::string name;
  std::string kind;
  segmentation::PixelSet pixels;  // its usable pixels
};

// How a user segments objects of one kind: the channel and what constrains it.
struct Recipe {
  segmentation::GrowSettings grow;
  bool lasso = false;         // a rectangle-like lasso around the object, with a margin
  bool foot_barrier = false;  // a line round the foot, where the object meets the ground
};

// The recipe for objects of `kind` ("wall", "window", "lamp_post", …).
Recipe recipe_for(const std::string& kind);

// One click's grow: its time and the size of the region it grew.
struct Click {
  double seconds = 0.0;
  std::size_t pixels = 0;
};

struct SessionResult {
  segmentation::PixelSet region;
  int operations = 0;         // lassos, barriers and clicks
  std::vector<Click> clicks;  // each click's grow alone
  double iou = 0.0;
  // After each click: the operations made so far and the IoU reached.
  std::vector<std::pair<int, double>> progress;
};

// Plays the session of `target` on `grid` with at most `max_operations`:
// the recipe's lasso and barrier, a click at the object's most interior
// pixel, then, while operations remain and a missed part of the object
// larger than 2 % of it is visible, a click inside the largest such part.
SessionResult play_session(const segmentation::SegmentationGrid& grid,
                           segmentation::RegionGrower& grower, const TargetObject& target,
                           const Recipe& recipe, int max_operations);

// Intersection over union of two pixel sets (0 when both are empty).
double iou(const segmentation::PixelSet& a, const segmentation::PixelSet& b);

}  // namespace scanbench::bench
