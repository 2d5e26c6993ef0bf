// The render model (docs/architecture.md): everything the renderer draws,
// read from a project and cut into spatial tiles (spatial_tiles.hpp).
//
// Which points: the in-model points of every scan (valid, not mixed pixels;
// acquisition/geometry/scan_geometry.hpp), only those the merge kept where the merge
// ran, none marked deleted. Each object's points, over all scans, and the
// points no object owns are tiled on their own, so a tile belongs to exactly
// one node and culling can walk the tree. Hidden objects (hidden themselves
// or below a hidden group) keep their tiles, marked not shown: the renderer
// skips them, and showing them again needs no rebuild.
//
// Coordinates: floats relative to `origin` (world = origin + position), an
// origin at the first scan's scanner rounded to metres, so georeferenced
// sites keep sub-millimetre precision in the float buffers.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

#include "modeling/store/project.hpp"
#include "render/spatial_tiles.hpp"

namespace scanbench::render {

// Point attributes, tile after tile, each tile's points in level-of-detail
// order; all arrays as long as `position`.
struct RenderPoints {
  std::vector<Eigen::Vector3f> position;  // [m] from the origin
  std::vector<Eigen::Vector3f> normal;    // world frame, towards its scanner; zero: unknown
  // The splat: an ellipse in the point's tangent plane covering its share of
  // the surface. Seen at incidence θ, a sample's cell stretches by 1 / cos θ
  // along the surface's slope away from the scanner (the major axis) and
  // not across it, so the ground far from a scanner gets long thin splats
  // instead of round ones that leave gaps between the scan's rows.
  std::vector<Eigen::Vector2f> radii_m;     // (across, along the major axis) [m]
  std::vector<Eigen::Vector3f> major_axis;  // unit, world frame; zero: round (radii equal)
  std::vector<std::array<std::uint8_t, 4>>
      rgba;  // shown colour: the scan's, its correction and its object's edit
             // applied (store/color_edit.hpp, modeling/color_pipeline.hpp); grey from intensity
             // without; alpha 255
  std::vector<float> intensity;     // [0, 1]: the scan's 2nd–98th percentile spread
  std::vector<std::uint32_t> node;  // the owning object, 0 for none

  std::size_t size() const { return position.size(); }
  // Room for `n` points in every array.
  void reserve(std::size_t n);
};

struct RenderTile {
  std::int64_t node = 0;    // the object whose points these are; 0 for points no object owns
  std::uint32_t first = 0;  // into RenderPoints
  std::uint32_t count = 0;
  Eigen::AlignedBox3f box;  // from the origin
  float max_radius_m = 0.0f;  // the largest splat radius of its points
  NormalCone cone;
  // Level-of-detail order (order_for_level_of_detail): the first
  // level_ends[L] points are one per occupied cell of edge lod_cube_m / 2^L.
  std::vector<std::uint32_t> level_ends;
  float lod_cube_m = 0.0f;
};

// A node of the tree with what culling needs: its box over its tiles and its
// descendants' (hidden ones included, so that showing one needs no
// rebuild: a box at most too large, never too small), its tiles, and its
// children.
struct RenderNode {
  store::ObjectNode node;
  Eigen::AlignedBox3f box;            // empty when it shows nothing
  std::vector<std::size_t> tiles;     // into RenderModel::tiles
  std::vector<std::size_t> children;  // into RenderModel::nodes
  bool shown = true;                  // false when it or a group above it is hidden
};

struct RenderModelCounts {
  std::size_t in_model = 0;     // in-model points of all scans
  std::size_t merged_away = 0;  // dropped by the merge's keep masks
  std::size_t deleted = 0;      // marked deleted by the segmentation
  std::size_t hidden = 0;       // owned by hidden objects (in the model, not drawn)
};

struct RenderModel {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  RenderPoints points;
  std::vector<RenderTile> tiles;
  // The tree (every node, hidden ones too) and, last, a root holding the
  // points no object owns ("unassigned", id 0).
  std::vector<RenderNode> nodes;
  std::vector<std::size_t> roots;  // into nodes
  RenderModelCounts counts;
};

struct RenderModelSettings {
  TileLimits tiles;
  // The largest stretch of a splat along its major axis (1 / cos θ is
  // capped here): beyond it the scan's samples are too sparse and too noisy
  // to be a surface. Beyond 4 (the geometry stage's limit) only on ground
  // seen from above, and never past its neighbouring samples (sample_reach
  // in render_model.cpp): never on a silhouette.
  float max_stretch = 64.0f;
  bool merged_only = true;  // drop the points the merge dropped (where it ran)
};

// Reads every scan of the project (its geometry is required: a scan without
// it is refused with core::InputError naming it) and builds the model.
RenderModel build_render_model(const store::Project& project, const RenderModelSettings& settings);

// The model of points gathered elsewhere (a test's, a bench's): `points`
// relative to `origin`, each owned by points.node (0, or a node of `tree` not
// in it: none), tiled with `limits`. Counts: in_model = points.size().
RenderModel assemble_render_model(RenderPoints points, const Eigen::Vector3d& origin,
                                  const std::vector<store::ObjectNode>& tree,
                                  const TileLimits& limits);

}  // namespace scanbench::render
