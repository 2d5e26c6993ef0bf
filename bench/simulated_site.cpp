#include "bench/simulated_site.hpp"

#include "acquisition/simulation/random.hpp"
#include "acquisition/simulation/sites.hpp"

namespace scanbench::bench {

std::uint64_t scan_seed(int k) {
  return acquisition::sim::hash_combine(kSiteSeed, static_cast<std::uint64_t>(k));
}

acquisition::sim::ScanLighting scan_lighting(SiteLighting lighting, int k) {
  namespace sim = acquisition::sim;
  switch (lighting) {
    case SiteLighting::kReference:
      return sim::reference_lighting();
    case SiteLighting::kExposureOnly:
      return sim::one_sun_lighting(scan_seed(k));
    case SiteLighting::kPerScan:
      break;
  }
  return sim::random_lighting(scan_seed(k));
}

SimulatedSite simulate_site(const std::string& name, const acquisition::sim::ScannerModel& model,
                            int scan_count, SiteLighting lighting) {
  namespace sim = acquisition::sim;
  const sim::Site site = sim::make_site(name, kSiteSeed, scan_count);
  SimulatedSite out;
  out.name = name;
  out.true_poses = site.scan_poses;
  out.objects = site.scene.objects();
  for (int k = 0; k < scan_count; ++k) {
    sim::SimulatedScan simulated =
        sim::simulate_scan(site.scene, site.scan_poses[static_cast<std::size_t>(k)], model,
                           scan_lighting(lighting, k), scan_seed(k));
    out.geometry.push_back(acquisition::compute_geometry(simulated.scan).geometry);
    out.scans.push_back(std::move(simulated.scan));
    out.truth.push_back(std::move(simulated.truth));
  }
  return out;
}

}  // namespace scanbench::bench
