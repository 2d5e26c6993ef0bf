#include "bench/segmentation_sessions.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "segmentation/constraints.hpp"

namespace scanbench::bench {
namespace {

using segmentation::Channel;
using segmentation::GridShape;
using segmentation::PixelSet;

// The pixel of `pixels` farthest (in 8-connected steps) from every pixel
// outside the set, and that distance: where a user clicks to be sure to hit
// the object.
struct Interior {
  std::uint32_t pixel = 0;
  int depth = 0;
};

Interior most_interior(const GridShape& shape, const PixelSet& pixels) {
  // −1: outside the set; −2: inside, distance not yet known.
  std::vector<std::int32_t> distance(shape.pixel_count(), -1);
  for (const std::uint32_t p : pixels) distance[p] = -2;
  std::vector<std::uint32_t> frontier;
  for (const std::uint32_t p : pixels) {
    const int row = static_cast<int>(p / shape.columns), col = static_cast<int>(p % shape.columns);
    int inside = 0;
    shape.for_each_neighbour(row, col,
                             [&](int r, int c) { inside += distance[shape.index(r, c)] != -1; });
    if (inside < 8) frontier.push_back(p);
  }
  for (const std::uint32_t p : frontier) distance[p] = 0;
  Interior best{pixels.front(), 0};
  for (int step = 1; !frontier.empty(); ++step) {
    best = {frontier.front(), step - 1};
    std::vector<std::uint32_t> next;
    for (const std::uint32_t p : frontier) {
      const int row = static_cast<int>(p / shape.columns),
                col = static_cast<int>(p % shape.columns);
      shape.for_each_neighbour(row, col, [&](int r, int c) {
        const std::size_t q = shape.index(r, c);
        if (distance[q] != -2) return;
        distance[q] = step;
        next.push_back(static_cast<std::uint32_t>(q));
      });
    }
    frontier = std::move(next);
  }
  return best;
}

// The object's extent in the image: columns unwrapped so that an object
// across the seam is one interval (col_end may pass the last column).
struct ImageBox {
  long long col_begin = 0, col_end = 0;  // inclusive
  int row_begin = 0, row_end = 0;
};

ImageBox image_box(const GridShape& shape, const PixelSet& pixels) {
  std::vector<std::uint8_t> used(static_cast<std::size_t>(shape.columns), 0);
  ImageBox box{0, 0, shape.rows, -1};
  for (const std::uint32_t p : pixels) {
    used[p % shape.columns] = 1;
    box.row_begin = std::min(box.row_begin, static_cast<int>(p / shape.columns));
    box.row_end = std::max(box.row_end, static_cast<int>(p / shape.columns));
  }
  // The object spans everything but the longest run of unused columns
  // (circular when the grid wraps).
  const int n = shape.columns;
  const int laps = shape.wraps ? 2 : 1;
  int best_length = 0, best_end = -1, run = 0;
  for (int k = 0; k < laps * n; ++k) {
    run = used[static_cast<std::size_t>(k % n)] ? 0 : std::min(run + 1, n);
    if (run > best_length) best_length = run, best_end = k;
  }
  if (!shape.wraps || best_length == 0) {
    const auto first = std::find(used.begin(), used.end(), 1) - used.begin();
    const auto last = n - 1 - (std::find(used.rbegin(), used.rend(), 1) - used.rbegin());
    box.col_begin = first, box.col_end = last;
  } else {
    box.col_begin = (best_end + 1) % n;
    box.col_end = box.col_begin + (n - best_length) - 1;
  }
  return box;
}

segmentation::Polyline lasso_around(const ImageBox& box) {
  const double width = static_cast<double>(box.col_end - box.col_begin + 1);
  const double height = box.row_end - box.row_begin + 1;
  const double mx = std::max(3.0, 0.1 * width), my = std::max(3.0, 0.1 * height);
  const double x0 = static_cast<double>(box.col_begin) - mx - 0.5;
  const double x1 = static_cast<double>(box.col_end) + mx + 0.5;
  const double y0 = box.row_begin - my - 0.5, y1 = box.row_end + my + 0.5;
  return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
}

// A line tracing the object's foot, where a post meets the ground: one
// pixel below its lowest pixel in each column of its last rows (on the side
// where the points go down), and up either side as far as those rows reach.
segmentation::Polyline barrier_around_foot(const segmentation::SegmentationGrid& grid,
                                           const PixelSet& pixels, const ImageBox& box) {
  constexpr int kFootRows = 8;
  const auto columns = static_cast<std::uint32_t>(grid.shape.columns);
  const auto [low, high] = std::minmax_element(
      pixels.begin(), pixels.end(),
      [&](std::uint32_t a, std::uint32_t b) { return grid.point[a].z() < grid.point[b].z(); });
  const int down = *low / columns > *high / columns ? 1 : -1;
  const int foot = down > 0 ? box.row_end : box.row_begin;
  // The lowest row of each column of the foot, columns unwrapped like the box.
  std::vector<int> lowest(static_cast<std::size_t>(box.col_end - box.col_begin + 1), -1);
  for (const std::uint32_t p : pixels) {
    const int row = static_cast<int>(p / columns);
    if (std::abs(row - foot) >= kFootRows) continue;
    long long col = p % columns;
    if (col < box.col_begin) col += columns;
    int& extreme = lowest[static_cast<std::size_t>(col - box.col_begin)];
    if (extreme < 0 || (row - extreme) * down > 0) extreme = row;
  }
  // The sides rise from the foot row as long as they stay off the object.
  const std::vector<std::uint8_t> inside = segmentation::to_mask(grid.shape, pixels);
  const auto side_top = [&](long long col, int row) {
    const std::optional<int> c = grid.shape.column(col);
    int top = row;
    for (int k = 1; k <= kFootRows; ++k) {
      const int r = row - k * down;
      if (!c || r < 0 || r >= grid.shape.rows || inside[grid.shape.index(r, *c)]) break;
      top = r;
    }
    return static_cast<double>(top);
  };
  // Along the foot: a step to a row further down goes down first, a step up
  // goes across first, so the line never passes over the object's pixels.
  segmentation::Polyline line;
  for (std::size_t k = 0; k < lowest.size(); ++k) {
    if (lowest[k] < 0) continue;
    const double col = static_cast<double>(box.col_begin + static_cast<long long>(k));
    const double below = lowest[k] + down;
    if (line.empty()) {
      line.push_back({col - 1, side_top(static_cast<long long>(col) - 1, static_cast<int>(below))});
      line.push_back({col - 1, below});
    }
    const Eigen::Vector2d last = line.back();
    if ((below - last.y()) * down > 0) {
      line.push_back({last.x(), below});
    } else {
      line.push_back({col, last.y()});
    }
    line.push_back({col, below});
  }
  if (!line.empty()) {
    const Eigen::Vector2d last = line.back();
    const auto col = static_cast<long long>(last.x()) + 1;
    line.push_back({last.x() + 1, last.y()});
    line.push_back({last.x() + 1, side_top(col, static_cast<int>(last.y()))});
  }
  return line;
}

}  // namespace

Recipe recipe_for(const std::string& kind) {
  Recipe recipe;
  if (kind == "crown") {  // green foliage: many overlapping spheres
    recipe.grow = segmentation::default_grow_settings(Channel::kColor);
    recipe.grow.tolerance = 12.0;
    recipe.lasso = true;
  } else if (kind == "roof") {  // its own material, seen as a thin strip from below
    recipe.grow = segmentation::default_grow_settings(Channel::kColor);
  } else if (kind == "sign") {  // a panel parallel to the façade, 6 cm proud of it
    recipe.grow = segmentation::default_grow_settings(Channel::kNormal);
    recipe.grow.tolerance = 3.0;
    recipe.lasso = true;
  } else if (kind == "lamp_post") {  // one surface standing on the ground
    recipe.grow = segmentation::default_grow_settings(Channel::kRange);
    recipe.lasso = true;
    recipe.foot_barrier = true;
  } else if (kind == "trunk") {
    recipe.grow = segmentation::default_grow_settings(Channel::kColor);
    recipe.grow.tolerance = 12.0;
  } else if (kind == "car") {  // the same, often cut in two by what stands in front
    // Its panels meet at sharp creases, which break the default tolerance's
    // continuity at 40 m; 3 footprints take the body whole and still stop
    // at the barrier and the gap to the ground.
    recipe.grow = segmentation::default_grow_settings(Channel::kRange);
    recipe.grow.tolerance = 3.0;
    recipe.foot_barrier = true;
  } else {  // walls, doors, windows, the low wall: planes
    recipe.grow = segmentation::default_grow_settings(Channel::kNormal);
  }
  return recipe;
}

double iou(const PixelSet& a, const PixelSet& b) {
  const std::size_t common = segmentation::intersect(a, b).size();
  const std::size_t either = a.size() + b.size() - common;
  return either == 0 ? 0.0 : static_cast<double>(common) / static_cast<double>(either);
}

SessionResult play_session(const segmentation::SegmentationGrid& grid,
                           segmentation::RegionGrower& grower, const TargetObject& target,
                           const Recipe& recipe, int max_operations) {
  SessionResult session;
  const GridShape& shape = grid.shape;
  const ImageBox box = image_box(shape, target.pixels);
  segmentation::Constraints constraints;
  if (recipe.lasso) {
    constraints.lasso = lasso_around(box);
    ++session.operations;
  }
  if (recipe.foot_barrier) {
    constraints.barriers.push_back(barrier_around_foot(grid, target.pixels, box));
    ++session.operations;
  }
  const std::vector<std::uint8_t> open = segmentation::open_pixels(grid, constraints, {});
  PixelSet missed = target.pixels;
  while (session.operations < max_operations) {
    // The user clicks into the largest visibly missed part: at least 2 % of
    // the object (all of it at first), preferring parts thick enough to
    // click into over slivers along the region's edge.
    std::optional<Interior> click;
    for (const PixelSet& part : segmentation::separate(shape, missed)) {
      if (!session.region.empty() && part.size() * 50 < target.pixels.size()) break;
      const Interior inside = most_interior(shape, part);
      const bool thicker = click && click->depth < 2 && inside.depth >= 2;
      if (!click || thicker) click = inside;
    }
    if (!click) break;
    const auto start = std::chrono::steady_clock::now();
    const segmentation::GrowResult grown = grower.grow(click->pixel, recipe.grow, open);
    session.clicks.push_back(
        {std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
         grown.pixels.size()});
    ++session.operations;
    session.region = segmentation::unite(session.region, grown.pixels);
    const std::size_t missed_before = missed.size();
    missed = segmentation::subtract(missed, grown.pixels);
    // A click that took nothing of what was missed would be repeated in vain.
    session.progress.emplace_back(session.operations, iou(session.region, target.pixels));
    if (missed.size() == missed_before) break;
  }
  session.iou = iou(session.region, target.pixels);
  return session;
}

}  // namespace scanbench::bench
