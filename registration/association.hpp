// Correspondences between a sample cloud and a target scan under a pose
// guess: each sample is carried into the target frame and associated with a
// target pixel (registration/prepared_scan.hpp), then kept only when the two
// points are close and their normals agree.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "registration/prepared_scan.hpp"
#include "registration/sample_cloud.hpp"
#include "registration/target_patch.hpp"

namespace scanbench::registration {

struct Correspondence {
  std::uint32_t sample = 0;  // index into the SampleCloud
  // Row-major pixel of the target scan (usable); through a patch, the
  // pixel's position in the patch.
  std::int64_t pixel = 0;
};

struct AssociationGate {
  // Distance of T · sample from the target point's tangent plane at most
  // this; from the target point itself, at most this plus twice the point's
  // footprint radius.
  double max_distance_m = 0.5;
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
// core::parallel_for_index. With `nearest`, samples are associated
// with the closest indexed target sample instead of by projection.
std::vector<Correspondence> associate_samples(const SampleCloud& source, const PreparedScan& target,
                                              const Eigen::Isometry3d& T_target_source,
                                              const AssociationGate& gate, int threads,
                                              const SampleIndex* nearest = nullptr);

// associate_samples by projection through a patch of the target: the same
// matches as through the whole scan, or nullopt when a sample falls on a
// pixel that the patch does not hold (the pose moved too far from the
// patch's; then only the whole scan can tell).
std::optional<std::vector<Correspondence>> associate_samples(
    const SampleCloud& source, const PatchedTarget& target,
    const Eigen::Isometry3d& T_target_source, const AssociationGate& gate, int threads);

// The share of the samples seen by the target scan that the pose puts in
// the target's free space: in front of the surface that the target measured
// on that beam, by more than tolerance_m, plus twice the pixel's footprint,
// plus the range change across half a pixel on an oblique surface. Only
// pixels with a normal and an incidence below 80° count (at grazing
// incidence the range of a neighbouring beam is too uncertain).
// The target's beam passed through where such a sample would sit, so a pose
// that puts many samples there is wrong however well the rest fits; a
// dominant plane (the ground) fits under many wrong poses, free space does
// not. 0 for targets
// without a spherical grid. (Huber and Hebert 2003 use the same test to
// verify pairwise matches.)
double free_space_violation(const SampleCloud& source, const PreparedScan& target,
                            const Eigen::Isometry3d& T_target_source, double tolerance_m,
                            int threads);

// associate_samples by projection, and in the same pass the free-space test
// with the gate's distance as its tolerance (0 for targets without a
// spherical grid).
struct ProjectiveAssociation {
  std::vector<Correspondence> matches;
  double free_space_violation = 0.0;
};
ProjectiveAssociation associate_with_free_space(const SampleCloud& source,
                                                const PreparedScan& target,
                                                const Eigen::Isometry3d& T_target_source,
                                                const AssociationGate& gate, int threads);
// The same through a patch; nullopt as for associate_samples.
std::optional<ProjectiveAssociation> associate_with_free_space(
    const SampleCloud& source, const PatchedTarget& target,
    const Eigen::Isometry3d& T_target_source, const AssociationGate& gate, int threads);

// A correspondence as the point-to-plane costs read it: the source sample
// and the target point and normal, in double.
struct PlaneCorrespondence {
  Eigen::Vector3d sample;  // source scan frame [m]
  Eigen::Vector3d point;   // target scan frame [m]
  Eigen::Vector3d normal;  // target scan frame, unit
};
std::vector<PlaneCorrespondence> plane_correspondences(const SampleCloud& source,
                                                       const PreparedScan& target,
                                                       std::span<const Correspondence> matches);
std::vector<PlaneCorrespondence> plane_correspondences(const SampleCloud& source,
                                                       const PatchedTarget& target,
                                                       std::span<const Correspondence> matches);

// Signed distance [m] of the sample, moved by T_target_source, from the
// target's tangent plane.
inline double plane_distance(const PlaneCorrespondence& c,
                             const Eigen::Isometry3d& T_target_source) {
  return c.normal.dot(T_target_source * c.sample - c.point);
}

}  // namespace scanbench::registration
