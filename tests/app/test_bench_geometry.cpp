// Smoke test of `scanbench bench geometry`: the suite runs end to end on a
// tiny scan and reports every field issue #4 names. Its figures are not
// checked: speed and accuracy are measured by the bench itself, not asserted.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "support/test_support.hpp"

namespace scanbench {
namespace {

struct CliResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

// Runs the scanbench binary with fixed, quote-free arguments; stdout and
// stderr go through files in `dir`.
CliResult run_bench_cli(const test::ScratchDir& dir, const std::string& args) {
  const std::filesystem::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string command = std::string("'") + SCANBENCH_BINARY + "' " + args + " >'" +
                              out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(command.c_str());
  CliResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = test::read_file_bytes(out);
  result.err = test::read_file_bytes(err);
  return result;
}

TEST(BenchGeometry, SmokeRunReportsEveryMethodAndField) {
  test::ScratchDir dir;
  const CliResult result = run_bench_cli(dir, "bench geometry --json --smoke");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json bench = nlohmann::json::parse(result.out);
  EXPECT_EQ(bench["suite"], "geometry");
  EXPECT_EQ(bench["columns"], 360);
  EXPECT_EQ(bench["rows"], 90);
  EXPECT_GT(bench["points"].get<double>(), 0.0);
  for (const char* ratio :
       {"speedup_vs_pcl_integral_covariance", "speedup_vs_pcl_integral_average_3d_gradient"})
    EXPECT_TRUE(bench.contains(ratio)) << ratio;
  for (const char* method :
       {"ours", "pcl_integral_covariance", "pcl_integral_average_3d_gradient", "pcl_knn_omp"}) {
    ASSERT_TRUE(bench.contains(method)) << method;
    for (const char* field : {"median_error_deg", "p95_error_deg", "planar_median_error_deg",
                              "coverage", "points_per_second"})
      EXPECT_TRUE(bench[method][field].is_number()) << method << "." << field;
    const double coverage = bench[method]["coverage"].get<double>();
    EXPECT_GT(coverage, 0.0) << method;
    EXPECT_LE(coverage, 1.0) << method;
  }
  for (const char* field : {"mixed_pixel_recall", "mixed_pixel_false_rate"})
    EXPECT_TRUE(bench["ours"][field].is_number()) << field;
}

}  // namespace
}  // namespace scanbench
