#include "registration/association.hpp"

#include <algorithm>

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
  const auto max_squared = static_cast<float>(gate.max_distance_m * gate.max_distance_m);
  const auto min_cos = static_cast<float>(gate.min_normal_cos);
  for (std::size_t s = begin; s < end; ++s) {
    const Eigen::Vector3f p = T * source.points[s];
    const std::int64_t pixel = target_pixel(target, nearest, p);
    if (pixel < 0) continue;
    const auto k = static_cast<std::size_t>(pixel);
    if (!target.usable[k]) continue;
    if ((target.points[k] - p).squaredNorm() > max_squared) continue;
    if ((T.linear() * source.normals[s]).dot(target.geometry->normal[k]) < min_cos) continue;
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

}  // namespace scanbench::registration
