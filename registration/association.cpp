#include "registration/association.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <numbers>

#include "core/parallel.hpp"

namespace scanbench::registration {
namespace {

constexpr int kBlock = 4096;  // samples per parallel task

// Slot of a pixel that a patch does not hold.
constexpr std::int64_t kUncovered = -2;

// What association reads of a target, by slot: a whole prepared scan,
// whose slots are its pixels...
class WholeTarget {
 public:
  explicit WholeTarget(const PreparedScan& target) : target_(target) {}
  bool spherical() const { return target_.grid.has_value(); }
  // The slot associated with `p` (target frame), -1 for none.
  std::int64_t slot_of(const Eigen::Vector3f& p) const { return associate(target_, p); }
  bool usable(std::size_t k) const { return target_.usable[k] != 0; }
  const Eigen::Vector3f& point(std::size_t k) const { return target_.points[k]; }
  const Eigen::Vector3f& normal(std::size_t k) const { return target_.geometry->normal[k]; }
  float footprint_m(std::size_t k) const { return target_.geometry->footprint_m[k]; }
  float range_m(std::size_t k) const { return target_.scan->range_m[k]; }
  double half_diagonal_rad() const { return target_.grid->half_diagonal_rad(); }

 private:
  const PreparedScan& target_;
};

// ... or a patch of one, whose slots are its positions (kUncovered: the
// pixel is not among them).
class PatchView {
 public:
  explicit PatchView(const PatchedTarget& target) : grid_(target.grid), patch_(target.patch) {}
  bool spherical() const { return true; }
  std::int64_t slot_of(const Eigen::Vector3f& p) const {
    const std::int64_t pixel = grid_.pixel_of(p);
    if (pixel < 0) return -1;
    const std::int64_t slot = patch_.slot_of(pixel);
    return slot < 0 ? kUncovered : slot;
  }
  bool usable(std::size_t k) const { return patch_.usable[k] != 0; }
  const Eigen::Vector3f& point(std::size_t k) const { return patch_.points[k]; }
  const Eigen::Vector3f& normal(std::size_t k) const { return patch_.normals[k]; }
  float footprint_m(std::size_t k) const { return patch_.footprint_m[k]; }
  float range_m(std::size_t k) const { return patch_.range_m[k]; }
  double half_diagonal_rad() const { return grid_.half_diagonal_rad(); }

 private:
  const acquisition::SphericalGrid& grid_;
  const TargetPatch& patch_;
};

// The per-sample test of free_space_violation (association.hpp).
template <typename Target>
class FreeSpaceTest {
 public:
  FreeSpaceTest(const Target& target, double tolerance_m)
      : target_(target),
        tolerance_(static_cast<float>(tolerance_m)),
        half_diagonal_(static_cast<float>(target.half_diagonal_rad())),
        // Beyond this incidence a surface's range along neighbouring beams
        // is too uncertain to testify about free space.
        min_cos_incidence_(std::cos(80.0f * std::numbers::pi_v<float> / 180.0f)) {}

  // Counts sample p (target frame) on slot k into `seen` and `violations`.
  void count(std::size_t k, const Eigen::Vector3f& p, std::size_t& seen,
             std::size_t& violations) const {
    if (!target_.usable(k)) return;
    const float range = target_.range_m(k);
    const float cos_incidence = std::abs(target_.normal(k).dot(target_.point(k))) / range;
    if (cos_incidence < min_cos_incidence_) return;
    ++seen;
    // The sample's beam is up to half a pixel diagonal off the pixel's: on
    // an oblique surface that shifts the range by r · angle · tan θ.
    const float tan_incidence = std::sqrt(1.0f - cos_incidence * cos_incidence) / cos_incidence;
    const float slack =
        tolerance_ + 2.0f * target_.footprint_m(k) + range * half_diagonal_ * tan_incidence;
    if (p.norm() < range - slack) ++violations;
  }

 private:
  const Target& target_;
  float tolerance_;
  float half_diagonal_;
  float min_cos_incidence_;
};

struct BlockResult {
  std::vector<Correspondence> matches;
  std::size_t seen = 0;  // free-space test
  std::size_t violations = 0;
  bool uncovered = false;  // a sample fell outside the target's patch
};

// Associates samples [begin, end); with `free_space`, also counts them into
// its test (projective association only). With `nearest` (whole targets
// only), by the closest indexed sample instead of by projection.
template <typename Target>
void associate_block(const SampleCloud& source, const Target& target, const SampleIndex* nearest,
                     const Eigen::Isometry3f& T, const AssociationGate& gate,
                     const FreeSpaceTest<Target>* free_space, std::size_t begin, std::size_t end,
                     BlockResult& out) {
  const auto max_distance = static_cast<float>(gate.max_distance_m);
  const auto min_cos = static_cast<float>(gate.min_normal_cos);
  for (std::size_t s = begin; s < end; ++s) {
    const Eigen::Vector3f p = T * source.points[s];
    std::int64_t slot = 0;
    if (nearest == nullptr) {
      slot = target.slot_of(p);
    } else {
      const std::int64_t i = nearest->index.nearest(p);
      slot = i < 0 ? -1 : nearest->pixels[static_cast<std::size_t>(i)];
    }
    if (slot == kUncovered) {
      out.uncovered = true;
      return;
    }
    if (slot < 0) continue;
    const auto k = static_cast<std::size_t>(slot);
    if (free_space != nullptr) free_space->count(k, p, out.seen, out.violations);
    if (!target.usable(k)) continue;
    const Eigen::Vector3f offset = p - target.point(k);
    const Eigen::Vector3f& normal = target.normal(k);
    if (std::abs(normal.dot(offset)) > max_distance) continue;
    // Along the surface the match may be off by the pixel's footprint, which
    // grows at grazing incidence; a fixed distance would drop the oblique
    // façades that two far-apart scans share.
    const float along = max_distance + 2.0f * target.footprint_m(k);
    if (offset.squaredNorm() > along * along) continue;
    if ((T.linear() * source.normals[s]).dot(normal) < min_cos) continue;
    out.matches.push_back({static_cast<std::uint32_t>(s), slot});
  }
}

// Every block of samples in parallel; the blocks' results in sample order.
template <typename Target>
std::vector<BlockResult> associate_blocks(const SampleCloud& source, const Target& target,
                                          const Eigen::Isometry3d& T_target_source,
                                          const AssociationGate& gate, int threads,
                                          const SampleIndex* nearest,
                                          const FreeSpaceTest<Target>* free_space) {
  const Eigen::Isometry3f T = T_target_source.cast<float>();
  const int blocks = static_cast<int>((source.size() + kBlock - 1) / kBlock);
  std::vector<BlockResult> found(static_cast<std::size_t>(blocks));
  core::parallel_for_index(blocks, threads, [&](int b) {
    const std::size_t begin = static_cast<std::size_t>(b) * kBlock;
    const std::size_t end = std::min(source.size(), begin + kBlock);
    associate_block(source, target, nearest, T, gate, free_space, begin, end,
                    found[static_cast<std::size_t>(b)]);
  });
  return found;
}

bool any_uncovered(const std::vector<BlockResult>& blocks) {
  return std::any_of(blocks.begin(), blocks.end(),
                     [](const BlockResult& block) { return block.uncovered; });
}

std::vector<Correspondence> concatenated(const std::vector<BlockResult>& blocks) {
  std::vector<Correspondence> all;
  for (const BlockResult& block : blocks) {
    all.insert(all.end(), block.matches.begin(), block.matches.end());
  }
  return all;
}

double violation_share(const std::vector<BlockResult>& blocks) {
  std::size_t seen = 0, violations = 0;
  for (const BlockResult& block : blocks) seen += block.seen, violations += block.violations;
  return seen > 0 ? static_cast<double>(violations) / static_cast<double>(seen) : 0.0;
}

// associate_with_free_space on either kind of target; nullopt when a sample
// fell outside a patch.
template <typename Target>
std::optional<ProjectiveAssociation> associate_projectively(
    const SampleCloud& source, const Target& target, const Eigen::Isometry3d& T_target_source,
    const AssociationGate& gate, int threads) {
  std::optional<FreeSpaceTest<Target>> test;
  if (target.spherical()) test.emplace(target, gate.max_distance_m);
  const std::vector<BlockResult> blocks = associate_blocks(
      source, target, T_target_source, gate, threads, nullptr, test ? &*test : nullptr);
  if (any_uncovered(blocks)) return std::nullopt;
  return ProjectiveAssociation{concatenated(blocks), test ? violation_share(blocks) : 0.0};
}

template <typename Target>
std::vector<PlaneCorrespondence> planes_of(const SampleCloud& source, const Target& target,
                                           std::span<const Correspondence> matches) {
  std::vector<PlaneCorrespondence> planes;
  planes.reserve(matches.size());
  for (const Correspondence& c : matches) {
    const auto k = static_cast<std::size_t>(c.pixel);
    const Eigen::Vector3f& point = target.point(k);
    const Eigen::Vector3f& normal = target.normal(k);
    planes.push_back(
        {source.points[c.sample].cast<double>(), point.cast<double>(), normal.cast<double>()});
  }
  return planes;
}

}  // namespace

SampleIndex::SampleIndex(const SampleCloud& target)
    : index(target.points, std::vector<std::uint8_t>(target.size(), 1)), pixels(target.pixels) {}

std::vector<Correspondence> associate_samples(const SampleCloud& source, const PreparedScan& target,
                                              const Eigen::Isometry3d& T_target_source,
                                              const AssociationGate& gate, int threads,
                                              const SampleIndex* nearest) {
  return concatenated(associate_blocks<WholeTarget>(source, WholeTarget(target), T_target_source,
                                                    gate, threads, nearest, nullptr));
}

std::optional<std::vector<Correspondence>> associate_samples(
    const SampleCloud& source, const PatchedTarget& target,
    const Eigen::Isometry3d& T_target_source, const AssociationGate& gate, int threads) {
  const std::vector<BlockResult> blocks = associate_blocks<PatchView>(
      source, PatchView(target), T_target_source, gate, threads, nullptr, nullptr);
  if (any_uncovered(blocks)) return std::nullopt;
  return concatenated(blocks);
}

ProjectiveAssociation associate_with_free_space(const SampleCloud& source,
                                                const PreparedScan& target,
                                                const Eigen::Isometry3d& T_target_source,
                                                const AssociationGate& gate, int threads) {
  return *associate_projectively(source, WholeTarget(target), T_target_source, gate, threads);
}

std::optional<ProjectiveAssociation> associate_with_free_space(
    const SampleCloud& source, const PatchedTarget& target,
    const Eigen::Isometry3d& T_target_source, const AssociationGate& gate, int threads) {
  return associate_projectively(source, PatchView(target), T_target_source, gate, threads);
}

double free_space_violation(const SampleCloud& source, const PreparedScan& target,
                            const Eigen::Isometry3d& T_target_source, double tolerance_m,
                            int threads) {
  // Every sample counts, so the normal test of the association is off.
  return associate_with_free_space(source, target, T_target_source, {tolerance_m, -1.0}, threads)
      .free_space_violation;
}

std::vector<PlaneCorrespondence> plane_correspondences(const SampleCloud& source,
                                                       const PreparedScan& target,
                                                       std::span<const Correspondence> matches) {
  return planes_of(source, WholeTarget(target), matches);
}

std::vector<PlaneCorrespondence> plane_correspondences(const SampleCloud& source,
                                                       const PatchedTarget& target,
                                                       std::span<const Correspondence> matches) {
  return planes_of(source, PatchView(target), matches);
}

}  // namespace scanbench::registration
