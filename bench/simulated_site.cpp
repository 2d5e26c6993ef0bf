#include "bench/simulated_site.hpp"

#include "acquisition/simulation/random.hpp"
#include "acquisition/simulation/sites.hpp"
#include "modeling/store/layer_store.hpp"
#include "modeling/store/project.hpp"
#include "modeling/store/typed_layers.hpp"
#include "registration/merge.hpp"
#include "registration/prepared_scan.hpp"

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

namespace {

// The keep masks of a merge of the first `count` scans at their true poses.
registration::MergeResult merge_first(const SimulatedSite& site, std::size_t count) {
  std::vector<registration::PreparedScan> prepared;
  for (std::size_t k = 0; k < count; ++k)
    prepared.push_back(registration::prepare_scan(site.scans[k], site.geometry[k], 0));
  const std::vector<Eigen::Isometry3d> poses(
      site.true_poses.begin(), site.true_poses.begin() + static_cast<std::ptrdiff_t>(count));
  return registration::merge_by_sampling_rate(prepared, poses, {});
}

}  // namespace

void store_site_project(const SimulatedSite& site, const std::filesystem::path& file,
                        std::optional<std::size_t> scans) {
  const std::size_t count = scans.value_or(site.scans.size());
  const registration::MergeResult merged = merge_first(site, count);
  store::Project project = store::Project::create(file);
  store::Project::Edit edit = project.begin_command("import", "{}");
  for (std::size_t k = 0; k < count; ++k) {
    const std::int64_t id = project.insert_scan(edit, store::encode_scan(site.scans[k]));
    for (const store::EncodedLayer& layer : store::encode_geometry(site.geometry[k]))
      project.put_layer(edit, id, layer);
    project.put_layer(edit, id,
                      store::encode_layer<std::uint8_t>(
                          store::layer::kKeep, store::ElementType::kU8, merged.scans[k].keep));
  }
  edit.commit("{}");
}

void add_site_scan(const SimulatedSite& site, std::size_t k, store::Project& project) {
  std::int64_t added = 0;
  {
    store::Project::Edit edit = project.begin_command("import", "{}");
    added = project.insert_scan(edit, store::encode_scan(site.scans[k]));
    for (const store::EncodedLayer& layer : store::encode_geometry(site.geometry[k]))
      project.put_layer(edit, added, layer);
    edit.commit("{}");
  }
  const registration::MergeResult merged = merge_first(site, k + 1);
  const std::vector<store::StoredScanSummary> stored = project.scans();
  store::Project::Edit edit = project.begin_command("merge", "{}");
  for (std::size_t j = 0; j <= k; ++j) {
    project.put_layer(edit, stored.at(j).id,
                      store::encode_layer<std::uint8_t>(
                          store::layer::kKeep, store::ElementType::kU8, merged.scans[j].keep));
  }
  edit.commit("{}");
}

}  // namespace scanbench::bench
