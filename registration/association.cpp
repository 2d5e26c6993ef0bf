#include "registration/association.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "core/parallel.hpp"

namespace scanbench::registration {
namespace {

constexpr int kBlock = 4096;  // samples per parallel task

// The per-sample test of free_space_violation (association.hpp).
class FreeSpaceTest {
 public:
  FreeSpaceTest(const PreparedScan& target, double tolerance_m)
      : target_(target),
        tolerance_(static_cast<float>(tolerance_m)),
        half_diagonal_(static_cast<float>(target.grid->half_diagonal_rad())),
        // Beyond this incidence a surface's range along neighbouring beams
        // is too uncertain to testify about free space.
        min_cos_incidence_(std::cos(80.0f * std::numbers::pi_v<float> / 180.0f)) {}

  // Counts sample p (target frame) on pixel k into `seen` and `violations`.
  void count(std::size_t k, const Eigen::Vector3f& p, std::size_t& seen,
             std::size_t& violations) const {
    if (!target_.usable[k]) return;
    const float range = target_.scan->range_m[k];
    const float cos_incidence =
        std::abs(target_.geometry->normal[k].dot(target_.points[k])) / range;
    if (cos_incidence < min_cos_incidence_) return;
    ++seen;
    // The sample's beam is up to half a pixel diagonal off the pixel's: on
    // an oblique surface that shifts the range by r · angle · tan θ.
    const float tan_incidence = std::sqrt(1.0f - cos_incidence * cos_incidence) / cos_incidence;
    const float slack = tolerance_ + 2.0f * target_.geometry->footprint_m[k] +
                        range * half_diagonal_ * tan_incidence;
    if (p.norm() < range - slack) ++violations;
  }

 private:
  const PreparedScan& target_;
  float tolerance_;
  float half_diagonal_;
  float min_cos_incidence_;
};

struct BlockResult {
  std::vector<Correspondence> matches;
  std::size_t seen = 0;  // free-space test
  std::size_t violations = 0;
};

std::int64_t target_pixel(const PreparedScan& target, const SampleIndex* nearest,
                          const Eigen::Vector3f& p) {
  if (nearest == nullptr) return associate(target, p);
  const std::int64_t k = nearest->index.nearest(p);
  return k < 0 ? -1 : nearest->pixels[static_cast<std::size_t>(k)];
}

// Associates samples [begin, end); with `free_space`, also counts them into
// its test (projective association only).
void associate_block(const SampleCloud& source, const PreparedScan& target,
                     const SampleIndex* nearest, const Eigen::Isometry3f& T,
                     const AssociationGate& gate, const FreeSpaceTest* free_space,
                     std::size_t begin, std::size_t end, BlockResult& out) {
  const auto max_distance = static_cast<float>(gate.max_distance_m);
  const auto min_cos = static_cast<float>(gate.min_normal_cos);
  for (std::size_t s = begin; s < end; ++s) {
    const Eigen::Vector3f p = T * source.points[s];
    const std::int64_t pixel = target_pixel(target, nearest, p);
    if (pixel < 0) continue;
    const auto k = static_cast<std::size_t>(pixel);
    if (free_space != nullptr) free_space->count(k, p, out.seen, out.violations);
    if (!target.usable[k]) continue;
    const Eigen::Vector3f offset = p - target.points[k];
    const Eigen::Vector3f& normal = target.geometry->normal[k];
    if (std::abs(normal.dot(offset)) > max_distance) continue;
    // Along the surface the match may be off by the pixel's footprint, which
    // grows at grazing incidence; a fixed distance would drop the oblique
    // façades that two far-apart scans share.
    const float along = max_distance + 2.0f * target.geometry->footprint_m[k];
    if (offset.squaredNorm() > along * along) continue;
    if ((T.linear() * source.normals[s]).dot(normal) < min_cos) continue;
    out.matches.push_back({static_cast<std::uint32_t>(s), pixel});
  }
}

}  // namespace

SampleIndex::SampleIndex(const SampleCloud& target)
    : index(target.points, std::vector<std::uint8_t>(target.size(), 1)), pixels(target.pixels) {}

namespace {

// Every block of samples in parallel; the blocks' results in sample order.
std::vector<BlockResult> associate_blocks(const SampleCloud& source, const PreparedScan& target,
                                          const Eigen::Isometry3d& T_target_source,
                                          const AssociationGate& gate, int threads,
                                          const SampleIndex* nearest,
                                          const FreeSpaceTest* free_space) {
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

}  // namespace

std::vector<Correspondence> associate_samples(const SampleCloud& source, const PreparedScan& target,
                                              const Eigen::Isometry3d& T_target_source,
                                              const AssociationGate& gate, int threads,
                                              const SampleIndex* nearest) {
  return concatenated(
      associate_blocks(source, target, T_target_source, gate, threads, nearest, nullptr));
}

ProjectiveAssociation associate_with_free_space(const SampleCloud& source,
                                                const PreparedScan& target,
                                                const Eigen::Isometry3d& T_target_source,
                                                const AssociationGate& gate, int threads) {
  if (!target.grid) return {associate_samples(source, target, T_target_source, gate, threads), 0.0};
  const FreeSpaceTest test(target, gate.max_distance_m);
  const std::vector<BlockResult> blocks =
      associate_blocks(source, target, T_target_source, gate, threads, nullptr, &test);
  return {concatenated(blocks), violation_share(blocks)};
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
  std::vector<PlaneCorrespondence> planes;
  planes.reserve(matches.size());
  for (const Correspondence& c : matches) {
    const auto k = static_cast<std::size_t>(c.pixel);
    planes.push_back({source.points[c.sample].cast<double>(), target.points[k].cast<double>(),
                      target.geometry->normal[k].cast<double>()});
  }
  return planes;
}

}  // namespace scanbench::registration
