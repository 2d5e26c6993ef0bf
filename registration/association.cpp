#include "registration/association.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "acquisition/parallel.hpp"

namespace scanbench::registration {
namespace {

constexpr int kBlock = 4096;  // samples per parallel task

std::int64_t target_pixel(const PreparedScan& target, const SampleIndex* nearest,
                          const Eigen::Vector3f& p) {
  if (nearest == nullptr) return associate(target, p);
  const std::int64_t k = nearest->index.nearest(p);
  return k < 0 ? -1 : nearest->pixels[static_cast<std::size_t>(k)];
}

void associate_block(const SampleCloud& source, const PreparedScan& target,
                     const SampleIndex* nearest, const Eigen::Isometry3f& T,
                     const AssociationGate& gate, std::size_t begin, std::size_t end,
                     std::vector<Correspondence>& out) {
  const auto max_distance = static_cast<float>(gate.max_distance_m);
  const auto min_cos = static_cast<float>(gate.min_normal_cos);
  for (std::size_t s = begin; s < end; ++s) {
    const Eigen::Vector3f p = T * source.points[s];
    const std::int64_t pixel = target_pixel(target, nearest, p);
    if (pixel < 0) continue;
    const auto k = static_cast<std::size_t>(pixel);
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
    out.push_back({static_cast<std::uint32_t>(s), pixel});
  }
}

}  // namespace

SampleIndex::SampleIndex(const SampleCloud& target)
    : index(target.points, std::vector<std::uint8_t>(target.size(), 1)), pixels(target.pixels) {}

std::vector<Correspondence> associate_samples(const SampleCloud& source, const PreparedScan& target,
                                              const Eigen::Isometry3d& T_target_source,
                                              const AssociationGate& gate, int threads,
                                              const SampleIndex* nearest) {
  const Eigen::Isometry3f T = T_target_source.cast<float>();
  const int blocks = static_cast<int>((source.size() + kBlock - 1) / kBlock);
  std::vector<std::vector<Correspondence>> found(static_cast<std::size_t>(blocks));
  acquisition::parallel_for_index(blocks, threads, [&](int b) {
    const std::size_t begin = static_cast<std::size_t>(b) * kBlock;
    const std::size_t end = std::min(source.size(), begin + kBlock);
    associate_block(source, target, nearest, T, gate, begin, end,
                    found[static_cast<std::size_t>(b)]);
  });
  std::vector<Correspondence> all;
  for (const auto& block : found) all.insert(all.end(), block.begin(), block.end());
  return all;
}

double free_space_violation(const SampleCloud& source, const PreparedScan& target,
                            const Eigen::Isometry3d& T_target_source, double tolerance_m,
                            int threads) {
  if (!target.grid) return 0.0;
  const Eigen::Isometry3f T = T_target_source.cast<float>();
  const auto tolerance = static_cast<float>(tolerance_m);
  const auto half_diagonal = static_cast<float>(target.grid->half_diagonal_rad());
  // Beyond this incidence a surface's range along neighbouring beams is too
  // uncertain to testify about free space.
  const float min_cos_incidence = std::cos(80.0f * std::numbers::pi_v<float> / 180.0f);
  const int blocks = static_cast<int>((source.size() + kBlock - 1) / kBlock);
  std::vector<std::array<std::size_t, 2>> counts(static_cast<std::size_t>(blocks), {0, 0});
  acquisition::parallel_for_index(blocks, threads, [&](int b) {
    const std::size_t begin = static_cast<std::size_t>(b) * kBlock;
    const std::size_t end = std::min(source.size(), begin + kBlock);
    auto& [seen, violations] = counts[static_cast<std::size_t>(b)];
    for (std::size_t s = begin; s < end; ++s) {
      const Eigen::Vector3f p = T * source.points[s];
      const std::int64_t pixel = target.grid->pixel_of(p);
      if (pixel < 0) continue;
      const auto k = static_cast<std::size_t>(pixel);
      if (!target.usable[k]) continue;
      const float range = target.scan->range_m[k];
      const float cos_incidence =
          std::abs(target.geometry->normal[k].dot(target.points[k])) / range;
      if (cos_incidence < min_cos_incidence) continue;
      ++seen;
      // The sample's beam is up to half a pixel diagonal off the pixel's: on
      // an oblique surface that shifts the range by r · angle · tan θ.
      const float tan_incidence = std::sqrt(1.0f - cos_incidence * cos_incidence) / cos_incidence;
      const float slack = tolerance + 2.0f * target.geometry->footprint_m[k] +
                          range * half_diagonal * tan_incidence;
      if (p.norm() < range - slack) ++violations;
    }
  });
  std::size_t seen = 0, violations = 0;
  for (const auto& [s, v] : counts) seen += s, violations += v;
  return seen > 0 ? static_cast<double>(violations) / static_cast<double>(seen) : 0.0;
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
