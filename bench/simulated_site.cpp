#include "bench/simulated_site.hpp"

#include "acquisition/simulation/random.hpp"
#include "acquisition/simulation/sites.hpp"

namespace scanbench::bench {

SimulatedSite simulate_site(const std::string& name, const acquisition::sim::ScannerModel& model,
                            int scan_count, SiteLighting lighting) {
  namespace sim = acquisition::sim;
  constexpr std::uint64_t kSiteSeed = 1;
  const sim::Site site = sim::make_site(name, kSiteSeed, scan_count);
  SimulatedSite out;
  out.name = name;
  out.true_poses = site.scan_poses;
  out.objects = site.scene.objects();
  for (int k = 0; k < scan_count; ++k) {
    const std::uint64_t seed = sim::hash_combine(kSiteSeed, static_cast<std::uint64_t>(k));
    sim::SimulatedScan simulated =
        sim::simulate_scan(site.scene, site.scan_poses[static_cast<std::size_t>(k)], model,
                           lighting == SiteLighting::kReference ? sim::reference_lighting()
                                                                : sim::random_lighting(seed),
                           seed);
    out.geometry.push_back(acquisition::compute_geometry(simulated.scan).geometry);
    out.scans.push_back(std::move(simulated.scan));
    out.truth.push_back(std::move(simulated.truth));
  }
  return out;
}

}  // namespace scanbench::bench
