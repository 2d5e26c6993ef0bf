#include "registration/edge_targets.hpp"

#include <cassert>
#include <memory>

namespace scanbench::registration {
namespace {

// Patches a visit keeps in memory besides the one in use: an edge's patch
// is read back once a visit, so few suffice.
constexpr std::size_t kPatchesKept = 4;

}  // namespace

void for_each_target(ScanStream& scans, std::span<const ScanEdge> edges,
                     const std::function<void(const PreparedScan&, std::size_t)>& visit) {
  std::map<int, std::vector<std::size_t>> by_target;
  for (std::size_t e = 0; e < edges.size(); ++e) by_target[edges[e].target].push_back(e);
  std::vector<int> order;
  for (const auto& [target, indices] : by_target) order.push_back(target);
  scans.plan(order);
  for (const auto& [target, indices] : by_target) {
    const std::shared_ptr<const PreparedScan> scan = scans.get(target);
    for (const std::size_t e : indices) visit(*scan, e);
  }
}

EdgePatches::EdgePatches(std::size_t scans, int margin)
    : margin_(margin), shelf_(0, kPatchesKept), grids_(scans) {}

void EdgePatches::make(const ScanEdge& edge, const SampleCloud& source, const PreparedScan& target,
                       const Eigen::Isometry3d& T_target_source) {
  drop(edge);
  if (!target.grid) return;
  const auto t = static_cast<std::size_t>(edge.target);
  assert(t < grids_.size() && "an edge between the registration's scans");
  if (!grids_[t]) grids_[t] = *target.grid;
  const std::size_t slot = shelf_.add(patch_of(source, target, T_target_source, margin_));
  // A patch the file could not take would stay in memory, and patches in
  // memory grow with the campaign: without the file, the edge goes without.
  if (shelf_.bytes_in_memory() > 0) {
    shelf_.release(slot);
    return;
  }
  slots_[edge] = slot;
}

void EdgePatches::drop(const ScanEdge& edge) {
  const auto found = slots_.find(edge);
  if (found == slots_.end()) return;
  shelf_.release(found->second);
  slots_.erase(found);
}

void EdgePatches::visit(ScanStream& scans, std::span<const ScanEdge> edges,
                        const std::function<bool(const PatchedTarget&, std::size_t)>& through_patch,
                        const std::function<void(const PreparedScan&, std::size_t)>& through_scan) {
  std::vector<ScanEdge> unpatched;
  std::vector<std::size_t> indices;  // of the unpatched edges in `edges`
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const auto found = slots_.find(edges[e]);
    if (found != slots_.end()) {
      const std::shared_ptr<const TargetPatch> patch = shelf_.get(found->second);
      const auto t = static_cast<std::size_t>(edges[e].target);
      if (through_patch({*grids_[t], *patch}, e)) {
        ++patch_visits_;
        continue;
      }
    }
    unpatched.push_back(edges[e]);
    indices.push_back(e);
  }
  scan_visits_ += unpatched.size();
  for_each_target(scans, unpatched, [&](const PreparedScan& target, std::size_t u) {
    through_scan(target, indices[u]);
  });
}

}  // namespace scanbench::registration
