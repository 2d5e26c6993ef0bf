// What the user limits a frame to (a clipping box and a slice) and how a
// frame may be culled and thinned: settings the frame plan
// (lod_frame_plan.hpp) and the shaders share. No OpenGL here.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>

namespace scanbench::render {

// What the user limits the drawing to, in the model's frame (metres from
// its origin): a clipping box, and a section plane with a thickness (a
// slice). A point is drawn when it lies in both.
struct Clipping {
  Eigen::AlignedBox3f box;                                    // empty (the default): no box
  Eigen::Vector3f section_normal = Eigen::Vector3f::UnitZ();  // unit
  float section_offset = 0.0f;                                // the plane: normal · p = offset
  float section_half_width = 0.0f;  // the slice's half thickness; 0: no plane

  bool active() const { return !box.isEmpty() || section_half_width > 0.0f; }
  bool keeps(const Eigen::Vector3f& p) const;
  // No point of `b` can be kept.
  bool excludes(const Eigen::AlignedBox3f& b) const;
};

struct CullSettings {
  Clipping clipping;
  bool frustum = true;          // nodes outside the view's frustum are left out
  bool backface = true;         // points facing away are left out (in the shaders)
  bool level_of_detail = true;  // nodes drawn as the prefix whose cells are lod_pixels wide
  float lod_pixels = 1.0f;      // [pixels] on screen
  // A still picture (no budget) draws cells of at most fine_lod_pixels
  // where the whole picture then holds at most fine_points points: a far
  // view gets several points a pixel, blended, as every point would give it
  // (on the campus's overview 0.5 px loses 0.1 dB against every point, 1 px
  // 0.5 dB); a near one, dense already, stays at lod_pixels (the street:
  // 3.6 M points at 0.5 px against 2.0 M, 3.6 s a frame on llvmpipe
  // against 2.4 s). 0: off.
  float fine_lod_pixels = 0.5f;
  std::size_t fine_points = 1500000;
  std::size_t budget = 0;       // points per frame; 0: no budget
  // Points a frame draws while nodes it wants are still being read (a
  // still camera refining: a quick preview, then the whole picture once
  // they are in, rather than every partial picture in full); 0: all it can.
  std::size_t preview_budget = 0;
};

}  // namespace scanbench::render
