// Loading a campaign's truth back (campaign.hpp): for tests and benchmarks
// that measure the pipeline against it.
#include <nlohmann/json.hpp>

#include "acquisition/formats/json_input.hpp"
#include "acquisition/rigid_transform.hpp"
#include "acquisition/simulation/campaign.hpp"
#include "acquisition/simulation/truth_images.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition::sim {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr std::uintmax_t kMaxTruthBytes = 64u << 20;

// Every lookup names the file and the key when it fails.
class TruthJson {
 public:
  explicit TruthJson(fs::path path)
      : path_(std::move(path)), root_(acquisition::read_json_file(path_, kMaxTruthBytes)) {}

  const json& root() const { return root_; }

  template <typename T>
  T get(const json& object, const char* key) const {
    if (!object.is_object() || !object.contains(key)) fail(key, "missing");
    try {
      return object.at(key).get<T>();
    } catch (const json::exception&) {
      fail(key, "has the wrong type");
    }
  }

  [[noreturn]] void fail(const char* key, const std::string& problem) const {
    throw core::InputError(
        path_.string(), {std::nullopt, std::nullopt, std::string("key \"") + key + "\""}, problem);
  }

  fs::path resolve(const std::string& relative) const { return path_.parent_path() / relative; }

 private:
  fs::path path_;
  json root_;
};

TruthScan load_scan(const TruthJson& file, const json& entry, int rows, int columns) {
  TruthScan scan;
  scan.name = file.get<std::string>(entry, "name");
  const Eigen::Matrix4d m =
      matrix_from_row_major(file.get<std::array<double, 16>>(entry, "T_world_scan"));
  if (const std::string problem = rigid_transform_problem(m); !problem.empty()) {
    file.fail("T_world_scan", problem);
  }
  scan.T_world_scan = to_isometry(m);
  const json files = file.get<json>(entry, "files");
  for (const char* format : {"ptx", "triplet"}) {
    if (files.contains(format))
      scan.scan_files.push_back(file.resolve(file.get<std::string>(files, format)));
  }
  const json truth = file.get<json>(entry, "truth");
  const TruthFiles images{file.resolve(file.get<std::string>(truth, "object_id")),
                          file.resolve(file.get<std::string>(truth, "normal")),
                          file.resolve(file.get<std::string>(truth, "range")),
                          file.resolve(file.get<std::string>(truth, "mixed"))};
  scan.truth = read_truth_images(images, rows, columns);
  return scan;
}

}  // namespace

CampaignTruth load_campaign_truth(const fs::path& truth_json) {
  const TruthJson file(truth_json);
  const json& root = file.root();
  if (file.get<std::string>(root, "format") != "scanbench-truth")
    file.fail("format", "is not scanbench-truth");
  if (file.get<int>(root, "version") != 1) file.fail("version", "is not 1");
  CampaignTruth campaign;
  campaign.site = file.get<std::string>(root, "site");
  campaign.seed = file.get<std::uint64_t>(root, "seed");
  const json scanner = file.get<json>(root, "scanner");
  campaign.rows = file.get<int>(scanner, "rows");
  campaign.columns = file.get<int>(scanner, "columns");
  if (campaign.rows <= 0 || campaign.columns <= 0)
    file.fail("scanner", "rows and columns must be positive");
  for (const json& entry : file.get<json>(root, "scans")) {
    campaign.scans.push_back(load_scan(file, entry, campaign.rows, campaign.columns));
  }
  for (const json& o : file.get<json>(root, "objects")) {
    campaign.objects.push_back({file.get<ObjectId>(o, "id"), file.get<std::string>(o, "name"),
                                file.get<ObjectId>(o, "parent"), file.get<std::string>(o, "kind")});
  }
  return campaign;
}

}  // namespace scanbench::acquisition::sim
