// Smoke tests of every `scanbench bench` suite: each runs
// end to end on a tiny scan and reports the fields its issue names. The
// figures are not checked: speed and accuracy are measured by the bench
// itself, never asserted in tests.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "app/cli_runner.hpp"
#include "support/test_support.hpp"

namespace scanbench {
namespace {

TEST(BenchGeometry, SmokeRunReportsEveryMethodAndField) {
  test::ScratchDir dir;
  const test::CliResult result = test::run_cli(dir, {"bench", "geometry", "--json", "--smoke"});
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

TEST(BenchRegistration, SmokeRunReportsBothMethodsAndEveryField) {
  test::ScratchDir dir;
  const test::CliResult result = test::run_cli(dir, {"bench", "registration", "--json", "--smoke"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json bench = nlohmann::json::parse(result.out);
  EXPECT_EQ(bench["suite"], "registration");
  for (const char* method : {"ours", "pcl_icp_point_to_plane"}) {
    ASSERT_TRUE(bench.contains(method)) << method;
    for (const char* field : {"max_rotation_error_deg", "max_translation_error_m",
                              "median_rotation_error_deg", "median_translation_error_m", "seconds"})
      EXPECT_TRUE(bench[method][field].is_number()) << method << "." << field;
  }
  EXPECT_TRUE(bench["ours"]["coarse_success_rate"].is_number());
  EXPECT_EQ(bench["ours"]["trials"], 1);
}

TEST(BenchMerge, SmokeRunReportsEveryField) {
  test::ScratchDir dir;
  const test::CliResult result = test::run_cli(dir, {"bench", "merge", "--json", "--smoke"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json bench = nlohmann::json::parse(result.out);
  EXPECT_EQ(bench["suite"], "merge");
  for (const char* field :
       {"redundant_removed_share", "coverage_before", "coverage_after", "points_per_second"}) {
    ASSERT_TRUE(bench["ours"][field].is_number()) << field;
    EXPECT_GE(bench["ours"][field].get<double>(), 0.0) << field;
  }
  EXPECT_LE(bench["ours"]["coverage_after"].get<double>(), 1.0);
}

TEST(BenchIo, SmokeRunPrintsOneJsonObject) {
  test::ScratchDir dir;
  const test::CliResult result = test::run_cli(dir, {"bench", "io", "--json", "--smoke"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json bench = nlohmann::json::parse(result.out);
  for (const char* field : {"ptx_read_mb_per_s", "ptx_write_mb_per_s", "points", "pcd_ascii",
                            "pcd_binary", "project_store_seconds", "project_load_seconds"}) {
    EXPECT_TRUE(bench.contains(field)) << field;
  }
  for (const char* format : {"pcd_ascii", "pcd_binary"}) {
    for (const char* field :
         {"bytes", "ours_points_per_s", "pcl_xyzi_points_per_s", "pcl_blob_points_per_s",
          "speedup_vs_pcl_xyzi", "speedup_vs_pcl_blob"}) {
      EXPECT_GT(bench[format][field].get<double>(), 0.0) << format << " " << field;
    }
  }
}

}  // namespace
}  // namespace scanbench
