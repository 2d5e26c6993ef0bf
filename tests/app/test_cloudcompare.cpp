// CloudCompare, what TLS users open scans with, as a real client of our
// exports: it reads our PTX and PLY of a simulated site near the origin,
// and the points it writes back (ASCII) are ours, as many and within its
// float precision (for PTX, that of the scan's pose applied in floats). Debian's CloudCompare has
// no E57 or LAS plug-in, so for those two formats a minimal check written here from the standards
// reads the header fields.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <tuple>

#include "app/cli_runner.hpp"
#include "support/test_support.hpp"

namespace scanbench::test {
namespace {

using Points = std::vector<std::array<double, 3>>;

// The first three numbers of every line of a text point file (CSV or
// CloudCompare's ASCII), after `skip` header lines.
Points read_xyz(const std::filesystem::path& path, int skip, char separator) {
  Points points;
  std::ifstream in(path);
  std::string line;
  for (int k = 0; k < skip; ++k) std::getline(in, line);
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::replace(line.begin(), line.end(), separator, ' ');
    std::istringstream fields(line);
    std::array<double, 3> p{};
    fields >> p[0] >> p[1] >> p[2];
    points.push_back(p);
  }
  return points;
}

// Opens `input` in CloudCompare (headless), merges its clouds and writes
// them as ASCII; returns the file it wrote.
std::filesystem::path through_cloudcompare(const ScratchDir& dir,
                                           const std::filesystem::path& input) {
  // Named after the whole input name: two inputs of one stem never share it.
  const std::filesystem::path out = dir / (input.filename().string() + "_cc.asc");
  // It splits file names at spaces (our scratch folders have some): it runs
  // in the folder, on bare names. Its own HOME: it keeps settings there.
  const std::string command = "cd " + shell_quote(dir.path().string()) +
                              " && HOME=" + shell_quote(dir.path().string()) +
                              " QT_QPA_PLATFORM=offscreen CloudCompare -SILENT -AUTO_SAVE OFF -O " +
                              shell_quote(input.filename().string()) +
                              " -MERGE_CLOUDS -C_EXPORT_FMT ASC -PREC 8 -SAVE_CLOUDS FILE " +
                              shell_quote(out.filename().string()) + " >cloudcompare.log 2>&1";
  EXPECT_EQ(std::system(command.c_str()), 0) << read_file_bytes(dir / "cloudcompare.log");
  // It may append the cloud's number to the name.
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    if (entry.path().filename().string().rfind(out.filename().string(), 0) == 0)
      return entry.path();
  }
  ADD_FAILURE() << "CloudCompare wrote no " << out << ":\n"
                << read_file_bytes(dir / "cloudcompare.log");
  return out;
}

// Every point of `theirs` matches one of `ours` within float precision, one
// to one: 2 float ulps of `magnitude` (the point's, by default), plus the 8
// printed decimals.
void expect_same_points(
    const Points& ours, const Points& theirs,
    const std::function<double(const std::array<double, 3>&)>& magnitude = [](const auto& p) {
      return std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    }) {
  ASSERT_EQ(theirs.size(), ours.size());
  std::multimap<std::tuple<long, long, long>, std::size_t> cells;  // 1 cm cells
  const auto cell = [](const std::array<double, 3>& p, int dx, int dy, int dz) {
    return std::tuple{std::lround(std::floor(p[0] / 0.01)) + dx,
                      std::lround(std::floor(p[1] / 0.01)) + dy,
                      std::lround(std::floor(p[2] / 0.01)) + dz};
  };
  for (std::size_t i = 0; i < ours.size(); ++i) cells.emplace(cell(ours[i], 0, 0, 0), i);
  std::vector<int> used(ours.size(), 0);
  std::size_t unmatched = 0;
  for (const auto& p : theirs) {
    const double tolerance = 2.4e-7 * magnitude(p) + 1e-8;
    bool found = false;
    for (int dx = -1; dx <= 1 && !found; ++dx) {
      for (int dy = -1; dy <= 1 && !found; ++dy) {
        for (int dz = -1; dz <= 1 && !found; ++dz) {
          const auto [first, last] = cells.equal_range(cell(p, dx, dy, dz));
          for (auto it = first; it != last && !found; ++it) {
            const auto& q = ours[it->second];
            if (used[it->second] == 0 && std::abs(p[0] - q[0]) <= tolerance &&
                std::abs(p[1] - q[1]) <= tolerance && std::abs(p[2] - q[2]) <= tolerance) {
              used[it->second] = 1;
              found = true;
            }
          }
        }
      }
    }
    unmatched += found ? 0 : 1;
  }
  EXPECT_EQ(unmatched, 0u);
}

std::uint64_t u64_at(const std::string& bytes, std::size_t offset) {
  std::uint64_t value = 0;
  std::memcpy(&value, bytes.data() + offset, 8);
  return value;
}

class CloudCompare : public ::testing::Test {
 protected:
  // Two simulated scans of the campus near the origin, exported four ways.
  static void SetUpTestSuite() {
    dir_ = new ScratchDir;
    const auto run = [](const std::vector<std::string>& args) {
      const CliResult result = run_cli(*dir_, args);
      ASSERT_EQ(result.exit_code, 0) << result.err;
    };
    const std::string sim = (*dir_ / "sim").string(), project = (*dir_ / "site.sbproj").string();
    run({"simulate", "--site", "campus", "--scans", "2", "--columns", "360", "--rows", "90",
         "--format", "ptx", "--out", sim});
    run({"import", project, sim + "/campus_scan_01.ptx", sim + "/campus_scan_02.ptx"});
    for (const char* format : {"csv", "ply", "ptx", "las", "e57"}) {
      run({"export", project, "--format", format, "-o",
           (*dir_ / (std::string("site.") + format)).string()});
    }
  }
  static void TearDownTestSuite() { delete dir_; }
  static ScratchDir* dir_;
};

ScratchDir* CloudCompare::dir_ = nullptr;

TEST_F(CloudCompare, ReadsOurPlyWithEveryPoint) {
  const Points ours = read_xyz(*dir_ / "site.csv", 1, ',');
  ASSERT_GT(ours.size(), 10000u);
  expect_same_points(ours, read_xyz(through_cloudcompare(*dir_, *dir_ / "site.ply"), 0, ' '));
}

// The farthest scanner from the origin among a PTX file's scans [m]: each
// scan's header gives its position on its third line.
double farthest_scanner(const std::filesystem::path& ptx) {
  std::ifstream in(ptx);
  double farthest = 0.0;
  long columns = 0, rows = 0;
  while (in >> columns >> rows) {
    std::array<double, 3> at{};
    in >> at[0] >> at[1] >> at[2];
    farthest = std::max(farthest, std::sqrt(at[0] * at[0] + at[1] * at[1] + at[2] * at[2]));
    std::string line;
    std::getline(in, line);  // the rest of the position's line
    for (long k = 0; k < 7 + columns * rows; ++k) std::getline(in, line);  // axes, pose, points
  }
  return farthest;
}

// CloudCompare reads a PTX scan's points in its own frame and applies the
// pose in single precision, so its rounding scales with the point's range
// and the scanner's distance from the origin, not with the point's own
// magnitude: up to 3.2 µm off for a point 12 m from the origin (2.7·10⁻⁷
// of it). The bound is 2 float ulps of |p| + 2 |t| (the range is at most
// |p| + |t|), |t| the farthest scanner: 11 m here, so about 17 µm at most.
TEST_F(CloudCompare, ReadsOurPtxWithEveryPoint) {
  const Points ours = read_xyz(*dir_ / "site.csv", 1, ',');
  const double scanner = farthest_scanner(*dir_ / "site.ptx");
  ASSERT_GT(scanner, 1.0);
  expect_same_points(ours, read_xyz(through_cloudcompare(*dir_, *dir_ / "site.ptx"), 0, ' '),
                     [scanner](const auto& p) {
                       return std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) + 2.0 * scanner;
                     });
}

TEST_F(CloudCompare, OurLasHeaderHoldsThePointCount) {
  const std::string las = read_file_bytes(*dir_ / "site.las");
  ASSERT_GE(las.size(), 375u);
  EXPECT_EQ(las.substr(0, 4), "LASF");
  EXPECT_EQ(las[24], 1);  // version 1.4
  EXPECT_EQ(las[25], 4);
  EXPECT_EQ(las[104], 7);  // point data record format
  const std::uint32_t offset = static_cast<std::uint8_t>(las[96]) |
                               static_cast<std::uint8_t>(las[97]) << 8 |
                               static_cast<std::uint8_t>(las[98]) << 16;
  const std::uint16_t record =
      static_cast<std::uint8_t>(las[105]) | static_cast<std::uint8_t>(las[106]) << 8;
  EXPECT_EQ(u64_at(las, 247), read_xyz(*dir_ / "site.csv", 1, ',').size());
  EXPECT_EQ(las.size(), offset + u64_at(las, 247) * record);
}

TEST_F(CloudCompare, OurE57HeaderAndXmlAreWhatTheStandardLaysOut) {
  const std::string e57 = read_file_bytes(*dir_ / "site.e57");
  ASSERT_GE(e57.size(), 1024u);
  EXPECT_EQ(e57.substr(0, 8), "ASTM-E57");
  EXPECT_EQ(e57[8], 1);  // major version
  EXPECT_EQ(u64_at(e57, 16), e57.size()) << "filePhysicalLength";
  EXPECT_EQ(u64_at(e57, 40), 1024u) << "pageSize";
  EXPECT_EQ(e57.size() % 1024, 0u);
  // The XML section: logical bytes, 1020 of each 1024-byte page.
  std::string xml;
  for (std::uint64_t at = u64_at(e57, 24); xml.size() < u64_at(e57, 32); ++at) {
    if (at % 1024 < 1020) xml += e57[at];
  }
  EXPECT_THAT(xml, ::testing::StartsWith("<?xml"));
  EXPECT_THAT(xml, ::testing::HasSubstr("<e57Root type=\"Structure\" "
                                        "xmlns=\"http://www.astm.org/COMMIT/E57/2010-e57-v1.0\""));
  std::size_t grids = 0;
  for (std::size_t at = xml.find("recordCount=\"32400\""); at != std::string::npos;
       at = xml.find("recordCount=\"32400\"", at + 1)) {
    ++grids;
  }
  EXPECT_EQ(grids, 2u) << "two scans, every pixel of the 90 × 360 grid a record";
}

}  // namespace
}  // namespace scanbench::test
