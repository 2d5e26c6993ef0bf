// PCL's point-to-plane ICP in stages: pcl::IterativeClosestPointWithNormals
// has one maximum correspondence distance per align(), so the schedule of our
// ICP (registration/icp.cpp: a gate that starts wide and follows the
// residuals) is given to it as a sequence of align() calls, each from the
// pose the previous one reached, with its own distance. The target's kd-tree
// is built once and shared by every stage.
#include "bench/pcl_icp.hpp"

#include <pcl/console/print.h>
#include <pcl/correspondence.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/correspondence_rejection_median_distance.h>
#include <pcl/registration/correspondence_rejection_surface_normal.h>
#include <pcl/registration/icp.h>
#include <pcl/search/kdtree.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <vector>

#include "bench/pcl_sample_cloud.hpp"
#include "core/timing.hpp"
#include "registration/pose_parameters.hpp"

namespace scanbench::bench {
namespace {

using Point = pcl::PointNormal;
using Cloud = pcl::PointCloud<Point>;

// Exposes what pcl::Registration keeps protected: the correspondences of the
// last iteration, the iteration count of the last align(), and the fewest
// correspondences an iteration accepts.
class StagedIcp : public pcl::IterativeClosestPointWithNormals<Point, Point> {
 public:
  void set_min_correspondences(std::size_t count) {
    min_number_correspondences_ = static_cast<unsigned>(count);
  }
  const pcl::Correspondences& last_correspondences() const { return *correspondences_; }
  int last_iterations() const { return nr_iterations_; }
};

Eigen::Isometry3d to_isometry(const Eigen::Matrix4f& M) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      Eigen::Quaterniond(M.topLeftCorner<3, 3>().cast<double>()).normalized().toRotationMatrix();
  T.translation() = M.topRightCorner<3, 1>().cast<double>();
  return T;
}

// 1.4826 · median |point-to-plane distance| of `matches` at pose T: the
// robust σ our ICP sets its next gate from.
double robust_sigma(const Cloud& source, const Cloud& target, const pcl::Correspondences& matches,
                    const Eigen::Isometry3d& T) {
  if (matches.empty()) return 0.0;
  std::vector<double> distances;
  distances.reserve(matches.size());
  for (const pcl::Correspondence& match : matches) {
    const Point& s = source[static_cast<std::size_t>(match.index_query)];
    const Point& t = target[static_cast<std::size_t>(match.index_match)];
    const Eigen::Vector3d moved = T * Eigen::Vector3d(s.x, s.y, s.z);
    const Eigen::Vector3d normal(t.normal_x, t.normal_y, t.normal_z);
    distances.push_back(std::abs(normal.dot(moved - Eigen::Vector3d(t.x, t.y, t.z))));
  }
  auto middle = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2);
  std::nth_element(distances.begin(), middle, distances.end());
  return 1.4826 * *middle;
}

void configure(StagedIcp& icp, const PclIcpSettings& settings) {
  const registration::IcpSettings& schedule = settings.schedule;
  icp.setUseSymmetricObjective(settings.symmetric_objective);
  icp.setUseReciprocalCorrespondences(settings.reciprocal);
  icp.set_min_correspondences(schedule.min_correspondences);
  // PCL's convergence test within a stage: the same thresholds as ours (its
  // translation epsilon is squared, its rotation epsilon a cosine).
  icp.setTransformationEpsilon(schedule.stop_translation_m * schedule.stop_translation_m);
  icp.setTransformationRotationEpsilon(std::cos(schedule.stop_rotation_rad));
  if (settings.max_normal_angle_deg > 0.0) {
    auto rejector = pcl::make_shared<pcl::registration::CorrespondenceRejectorSurfaceNormal>();
    rejector->initializeDataContainer<pcl::PointXYZ, pcl::Normal>();
    rejector->setThreshold(std::cos(settings.max_normal_angle_deg * std::numbers::pi / 180.0));
    icp.addCorrespondenceRejector(rejector);
  }
  if (settings.median_factor > 0.0) {
    auto rejector = pcl::make_shared<pcl::registration::CorrespondenceRejectorMedianDistance>();
    rejector->setMedianFactor(settings.median_factor);
    icp.addCorrespondenceRejector(rejector);
  }
}

// The gate of the stage after one at `gate` [m] that left residuals of
// robust σ `sigma` [m].
double next_gate(double gate, double sigma, const PclIcpSettings& settings) {
  const registration::IcpSettings& s = settings.schedule;
  const double floor = std::max(s.min_gate_m, gate * s.min_gate_ratio);
  if (!settings.adaptive_gate) return floor;
  return std::clamp(s.distance_sigmas * sigma, floor, gate);
}

// PCL prints an error for every stage with too few correspondences; the
// result says so instead.
class QuietPcl {
 public:
  QuietPcl() : level_(pcl::console::getVerbosityLevel()) {
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  }
  ~QuietPcl() { pcl::console::setVerbosityLevel(level_); }
  QuietPcl(const QuietPcl&) = delete;
  QuietPcl& operator=(const QuietPcl&) = delete;

 private:
  pcl::console::VERBOSITY_LEVEL level_;
};

}  // namespace

PclIcpResult pcl_point_to_plane_icp(const registration::SampleCloud& source,
                                    const registration::SampleCloud& target,
                                    const Eigen::Isometry3d& initial,
                                    const PclIcpSettings& settings) {
  const registration::IcpSettings& schedule = settings.schedule;
  const Cloud::Ptr full = registration::to_pcl_cloud(source);
  const Cloud::Ptr rough =
      settings.thin_wide_stages
          ? registration::to_pcl_cloud(registration::thin(source, schedule.closest_point_samples))
          : full;
  const Cloud::Ptr target_cloud = registration::to_pcl_cloud(target);
  const QuietPcl quiet;
  const auto start = std::chrono::steady_clock::now();
  auto tree = pcl::make_shared<pcl::search::KdTree<Point>>();
  tree->setInputCloud(target_cloud);
  StagedIcp icp;
  configure(icp, settings);
  icp.setInputTarget(target_cloud);
  icp.setSearchMethodTarget(tree, true);
  PclIcpResult result;
  result.T_target_source = initial;
  double gate = std::max(schedule.initial_gate_m, schedule.min_gate_m);
  Cloud aligned;
  while (result.iterations < schedule.max_iterations) {
    const bool wide = gate > schedule.projective_gate_m;
    const Cloud::Ptr& samples = wide ? rough : full;
    icp.setInputSource(samples);
    icp.setMaxCorrespondenceDistance(gate);
    icp.setMaximumIterations(
        std::min(settings.iterations_per_stage, schedule.max_iterations - result.iterations));
    icp.align(aligned, result.T_target_source.matrix().cast<float>());
    ++result.stages;
    result.iterations += std::max(icp.last_iterations(), 1);
    result.final_gate_m = gate;
    if (icp.last_correspondences().size() < schedule.min_correspondences) break;
    const Eigen::Isometry3d next = to_isometry(icp.getFinalTransformation());
    const auto [rotation, translation] = registration::pose_change(result.T_target_source, next);
    result.T_target_source = next;
    const double used = gate;
    gate = next_gate(gate, robust_sigma(*samples, *target_cloud, icp.last_correspondences(), next),
                     settings);
    // PCL's own test ends a stage early, but judges the rotation in float
    // (a cosine that rounds to 1 below ~0.01°), so only the stage's whole
    // move decides that the pose no longer moves at this gate.
    if (rotation >= schedule.stop_rotation_rad || translation >= schedule.stop_translation_m) {
      continue;
    }
    const double last_gate =
        settings.adaptive_gate ? schedule.projective_gate_m : schedule.min_gate_m;
    if (used <= last_gate) {
      result.converged = true;
      break;
    }
    if (settings.adaptive_gate) gate = std::min(gate, schedule.projective_gate_m);
  }
  result.seconds = core::seconds_since(start);
  return result;
}

}  // namespace scanbench::bench
