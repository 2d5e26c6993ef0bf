// Correspondences between a sample cloud and a target scan under a pose
// guess: each sample is carried into the target frame and associated with a
// target pixel (registration/prepared_scan.hpp), then kept only when the two
// points are close and their normals agree.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "registration/prepared_scan.hpp"
#include "registration/sample_cloud.hpp"

namespace scanbench::registration {

struct Correspondence {
  std::uint32_t sample = 0;  // index into the SampleCloud
  std::int64_t pixel = 0;    // row-major pixel of the target scan (usable)
};

struct AssociationGate {
  double max_distance_m = 0.5;  // |T · sample − target point| at most this
  double min_normal_cos = 0.9;  // cos of the largest angle between the two normals
};

// Closest-point association into a sample of the target scan: a kd-tree
// query per sample instead of an O(1) projection, but with a wider basin, so
// ICP uses it while the pose is still far off.
struct SampleIndex {
  explicit SampleIndex(const SampleCloud& target);
  PointIndex index;
  std::vector<std::int64_t> pixels;  // target pixel of each indexed sample
};

// Every sample whose associated target pixel is usable and passes the gate,
// in sample order (deterministic for any thread count). T_target_source maps
// the samples' scan frame into the target's scan frame. `threads` as in
// acquisition::parallel_for_index. With `nearest`, samples are associated
// with the closest indexed target sample instead of by projection.
std::vector<Correspondence> associate_samples(const SampleCloud& source, const PreparedScan& target,
                                              const Eigen::Isometry3d& T_target_source,
                                              const AssociationGate& gate, int threads,
                                              const SampleIndex* nearest = nullptr);

}  // namespace scanbench::registration
