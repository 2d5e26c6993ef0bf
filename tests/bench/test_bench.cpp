// Smoke tests of every `scanbench bench` suite: each runs
// end to end on a tiny scan and reports the fields its issue names. The
// figures are not checked: speed and accuracy are measured by the bench
// itself, never asserted in tests.
#include <gtest/gtest.h>

#include <filesystem>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

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
  EXPECT_EQ(bench["site"], "campus");
  EXPECT_EQ(bench["columns"], 360);
  EXPECT_EQ(bench["rows"], 90);
  EXPECT_EQ(bench["scans"], 1);
  EXPECT_GT(bench["points"].get<double>(), 0.0);
  const char* const peers[] = {"pcl_integral_covariance", "pcl_integral_average_3d_gradient",
                               "pcl_knn_omp", "pcl_integral_covariance_smoothing_33",
                               "pcl_integral_average_3d_gradient_smoothing_33"};
  for (const std::string peer : peers) {
    EXPECT_TRUE(bench["speedup_vs_" + peer].is_number()) << peer;
    // The integral images run on one thread, and get a thread-for-thread ratio.
    EXPECT_EQ(bench.contains("speedup_vs_" + peer + "_1_thread"), peer != "pcl_knn_omp") << peer;
  }
  EXPECT_TRUE(bench["speedup_goal_1_thread"].is_number());
  for (const char* goal :
       {"median_below_every_pcl", "speedup_1_thread_at_least_5x_vs_average_3d_gradient",
        "mixed_recall_at_least_0_9_false_rate_at_most_0_01"})
    EXPECT_TRUE(bench["goals"][goal].is_boolean()) << goal;
  std::vector<std::string> methods = {"ours", "ours_1_thread"};
  methods.insert(methods.end(), std::begin(peers), std::end(peers));
  for (const std::string& method : methods) {
    ASSERT_TRUE(bench.contains(method)) << method;
    for (const char* field : {"median_error_deg", "p95_error_deg", "planar_median_error_deg",
                              "coverage", "points_per_second", "seconds", "threads"})
      EXPECT_TRUE(bench[method][field].is_number()) << method << "." << field;
    EXPECT_TRUE(bench[method]["settings"].is_object()) << method;
    const double coverage = bench[method]["coverage"].get<double>();
    EXPECT_GT(coverage, 0.0) << method;
    EXPECT_LE(coverage, 1.0) << method;
  }
  EXPECT_EQ(bench["ours_1_thread"]["threads"], 1);
  EXPECT_EQ(bench["pcl_integral_average_3d_gradient"]["threads"], 1);
  for (const char* method : {"ours", "ours_1_thread"}) {
    for (const char* field : {"mixed_pixel_recall", "mixed_pixel_false_rate", "truth_mixed_pixels"})
      EXPECT_TRUE(bench[method][field].is_number()) << method << "." << field;
    // Same estimator, same settings but threads: the same normals.
    EXPECT_EQ(bench[method]["median_error_deg"], bench["ours"]["median_error_deg"]) << method;
  }
}

TEST(BenchRegistration, SmokeRunReportsEveryMethodAndField) {
  test::ScratchDir dir;
  const test::CliResult result = test::run_cli(dir, {"bench", "registration", "--json", "--smoke"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json bench = nlohmann::json::parse(result.out);
  EXPECT_EQ(bench["suite"], "registration");
  EXPECT_EQ(bench["sites"], nlohmann::json::array({"campus"}));
  EXPECT_EQ(bench["scans_per_site"], 2);
  for (const char* field : {"columns", "rows", "threads", "speedup_goal"})
    EXPECT_TRUE(bench[field].is_number()) << field;
  for (const char* field : {"rotation_deg", "translation_m"})
    EXPECT_TRUE(bench["max_initial_error"][field].is_number()) << field;
  for (const char* method : {"ours", "ours_one_thread", "ours_pairwise", "ours_pairwise_one_thread",
                             "pcl_icp_point_to_plane"}) {
    ASSERT_TRUE(bench.contains(method)) << method;
    for (const char* field :
         {"max_rotation_error_deg", "max_translation_error_m", "median_rotation_error_deg",
          "median_translation_error_m", "seconds", "converged_pair_share"})
      EXPECT_TRUE(bench[method][field].is_number()) << method << "." << field;
    if (std::string(method) != "pcl_icp_point_to_plane") {
      EXPECT_TRUE(bench[method]["icp_seconds"].is_number()) << method;
    }
  }
  for (const char* field : {"coarse_success_rate", "coarse_accepted_but_wrong", "coarse_seconds"})
    EXPECT_TRUE(bench["ours"][field].is_number()) << field;
  EXPECT_EQ(bench["ours"]["trials"], 1);
  EXPECT_TRUE(bench["pcl_icp_point_to_plane"]["settings"].is_object());
  for (const char* ratio :
       {"fine_speedup_vs_pcl", "fine_speedup_vs_pcl_one_thread", "pairwise_speedup_vs_pcl",
        "pairwise_speedup_vs_pcl_one_thread", "pairwise_icp_speedup_vs_pcl",
        "pairwise_icp_speedup_vs_pcl_one_thread"})
    EXPECT_TRUE(bench[ratio].is_number()) << ratio;
  for (const char* goal :
       {"accuracy_within_0_02_deg_and_3_mm", "pairwise_speedup_one_thread_at_least_5x"})
    EXPECT_TRUE(bench["goals"][goal].is_boolean()) << goal;
  // Results do not depend on the thread count.
  for (const char* field : {"max_rotation_error_deg", "max_translation_error_m"}) {
    EXPECT_EQ(bench["ours_one_thread"][field], bench["ours"][field]) << field;
    EXPECT_EQ(bench["ours_pairwise_one_thread"][field], bench["ours_pairwise"][field]) << field;
  }
}

TEST(BenchMerge, SmokeRunReportsEveryField) {
  test::ScratchDir dir;
  const test::CliResult result = test::run_cli(dir, {"bench", "merge", "--json", "--smoke"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json bench = nlohmann::json::parse(result.out);
  EXPECT_EQ(bench["suite"], "merge");
  EXPECT_EQ(bench["site"], "campus");
  EXPECT_EQ(bench["scans"], 2);
  for (const char* field : {"columns", "rows", "threads"})
    EXPECT_TRUE(bench[field].is_number()) << field;
  for (const char* merge : {"ours", "ours_registered"}) {
    ASSERT_TRUE(bench.contains(merge)) << merge;
    for (const char* share : {"redundant_removed_share", "redundant_removed_share_by_spacing",
                              "unique_removed_share", "coverage_before", "coverage_after"}) {
      ASSERT_TRUE(bench[merge][share].is_number()) << merge << "." << share;
      EXPECT_GE(bench[merge][share].get<double>(), 0.0) << merge << "." << share;
      EXPECT_LE(bench[merge][share].get<double>(), 1.0) << merge << "." << share;
    }
    for (const char* field :
         {"coverage_drop", "coverage_samples", "points_per_second", "points", "kept_points",
          "truth_redundant_points", "truth_redundant_points_by_spacing", "truth_unique_points",
          "seconds", "prepare_seconds"})
      EXPECT_TRUE(bench[merge][field].is_number()) << merge << "." << field;
    EXPECT_GT(bench[merge]["coverage_samples"].get<double>(), 0.0) << merge;
    EXPECT_LE(bench[merge]["kept_points"].get<double>(), bench[merge]["points"].get<double>());
  }
  // Both merges are judged against the same truth and the same unmerged model.
  EXPECT_EQ(bench["ours"]["coverage_before"], bench["ours_registered"]["coverage_before"]);
  for (const char* field : {"max_rotation_error_deg", "max_translation_error_m", "seconds"})
    EXPECT_TRUE(bench["ours_registered"]["registration"][field].is_number()) << field;
  EXPECT_TRUE(bench["ours_registered"]["registration"]["converged"].is_boolean());
  for (const char* goals : {"goals", "goals_registered"}) {
    for (const char* goal :
         {"redundant_removed_share_at_least_0_9", "redundant_removed_share_by_spacing_at_least_0_9",
          "coverage_drop_at_most_0_005", "points_per_second_at_least_20m"})
      EXPECT_TRUE(bench[goals][goal].is_boolean()) << goals << "." << goal;
  }
}

TEST(BenchSegmentation, SmokeRunReportsEveryField) {
  test::ScratchDir dir;
  const test::CliResult result = test::run_cli(dir, {"bench", "segmentation", "--json", "--smoke"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json bench = nlohmann::json::parse(result.out);
  EXPECT_EQ(bench["suite"], "segmentation");
  const nlohmann::json& ours = bench["ours"];
  ASSERT_GE(ours["objects"].size(), 10u);
  for (const nlohmann::json& object : ours["objects"]) {
    for (const char* field : {"name", "kind", "channel"})
      EXPECT_TRUE(object[field].is_string()) << field;
    EXPECT_GE(object["iou"].get<double>(), 0.0);
    EXPECT_LE(object["iou"].get<double>(), 1.0);
    EXPECT_LE(object["operations"].get<int>(), 3);
    EXPECT_GT(object["pixels"].get<int>(), 0);
  }
  for (const char* field : {"mean_iou", "objects_at_least_0_95", "click_latency_ms_p50",
                            "click_latency_ms_p95", "clicks", "largest_region_pixels"})
    EXPECT_TRUE(ours[field].is_number()) << field;
  EXPECT_GE(bench["ours_held_out"]["objects"].size(), 10u);
  EXPECT_TRUE(bench["ours_held_out"]["mean_iou"].is_number());
  for (const char* peer : {"ours_auto", "pcl_region_growing", "pcl_region_growing_rgb"}) {
    EXPECT_GT(bench[peer]["seconds"].get<double>(), 0.0) << peer;
    EXPECT_EQ(bench[peer]["objects"].size(), ours["objects"].size()) << peer;
    EXPECT_LE(bench[peer]["mean_iou"].get<double>(), 1.0) << peer;
  }
  EXPECT_TRUE(bench["goals"]["click_latency_p95_at_most_16_ms"].is_boolean());
}

TEST(BenchRender, SmokeRunReportsEveryViewAndMode) {
  test::ScratchDir dir;
  const test::CliResult result = test::run_cli(
      dir, {"bench", "render", "--json", "--smoke", "--pictures", (dir / "pictures").string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json bench = nlohmann::json::parse(result.out);
  EXPECT_EQ(bench["suite"], "render");
  for (const char* view : {"closeup", "street", "overview"}) {
    for (const char* mode : {"points", "splats", "blended"}) {
      const nlohmann::json& figures = bench["views"][view][mode];
      for (const char* field : {"psnr_db", "ssim", "hole_fraction"})
        EXPECT_TRUE(figures[field].is_number()) << view << "." << mode << "." << field;
      EXPECT_GE(figures["hole_fraction"].get<double>(), 0.0);
      EXPECT_LE(figures["hole_fraction"].get<double>(), 1.0);
      EXPECT_TRUE(
          std::filesystem::exists(dir / "pictures" / (std::string(view) + "_" + mode + ".png")));
    }
    EXPECT_GT(bench["views"][view]["sampled_pixels"].get<int>(), 0) << view;
  }
  for (const char* field :
       {"frame_ms_culling_on", "frame_ms_culling_off", "culled_share", "culling_speedup"})
    EXPECT_GT(bench[field].get<double>(), 0.0) << field;
  for (const auto& [goal, met] : bench["goals"].items()) EXPECT_TRUE(met.is_boolean()) << goal;
}

TEST(BenchColor, SmokeRunReportsTheIssuesFields) {
  test::ScratchDir dir;
  const test::CliResult result = test::run_cli(dir, {"bench", "color", "--json", "--smoke"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json bench = nlohmann::json::parse(result.out);
  EXPECT_EQ(bench["suite"], "color");
  for (const char* field :
       {"before_delta_e", "after_delta_e", "after_delta_e_to_albedo", "reduction"})
    EXPECT_TRUE(bench[field].is_number()) << field;
  EXPECT_GT(bench["held_out_pairs"].get<int>(), 1000);
  // Even the smoke run's two small scans differ by exposure and white
  // balance only, which the fit undoes.
  EXPECT_LT(bench["after_delta_e"].get<double>(), bench["before_delta_e"].get<double>());
  EXPECT_EQ(bench["gain_offset"]["scans"].size(), 2u);
  EXPECT_TRUE(bench["goals"]["reduction_at_least_0_8"].is_boolean());
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

TEST(BenchScale, SmokeRunMeasuresEveryStageOfEachCampaignInItsOwnProcess) {
  test::ScratchDir dir;
  const test::CliResult result = test::run_cli(dir, {"bench", "scale", "--json", "--smoke"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json bench = nlohmann::json::parse(result.out);
  EXPECT_EQ(bench["suite"], "scale");
  ASSERT_EQ(bench["campaigns"].size(), 2u);
  for (const nlohmann::json& campaign : bench["campaigns"]) {
    EXPECT_GT(campaign["points"].get<double>(), 0.0);
    EXPECT_TRUE(campaign["pair_tests"].is_number());
    EXPECT_TRUE(campaign["max_rotation_error_deg"].is_number());
    for (const char* stage : {"import", "geometry", "register", "merge", "export_las"}) {
      const nlohmann::json& figures = campaign["stages"][stage];
      EXPECT_GT(figures["seconds"].get<double>(), 0.0) << stage;
      EXPECT_GT(figures["points_per_second"].get<double>(), 0.0) << stage;
      // Measured in the stage's own process.
      EXPECT_GT(figures["peak_rss_bytes"].get<double>(), 1e6) << stage;
    }
  }
  EXPECT_TRUE(bench["campaigns"][0]["stages"]["harmonize"].is_null());  // one scan: no pairs
  EXPECT_GT(bench["campaigns"][1]["stages"]["harmonize"]["seconds"].get<double>(), 0.0);
}

TEST(BenchLod, SmokeRunMeasuresTheBuildTheStreamingRendererAndEditsInPlace) {
  test::ScratchDir dir;
  const test::CliResult result = test::run_cli(dir, {"bench", "lod", "--json", "--smoke"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const nlohmann::json bench = nlohmann::json::parse(result.out);
  EXPECT_EQ(bench["suite"], "lod");
  EXPECT_GT(bench["points"].get<double>(), 0.0);
  EXPECT_GE(bench["threads"].get<int>(), 1);
  for (const char* field : {"build_points_per_second", "build_points_per_second_per_thread",
                            "build_peak_rss_bytes", "full_rebuild_seconds"}) {
    EXPECT_GT(bench[field].get<double>(), 0.0) << field;
  }
  EXPECT_GT(bench["one_thread"]["build_points_per_second"].get<double>(), 0.0);
  // The fly-through in its own process, and each view streamed to its
  // complete picture.
  for (const char* field :
       {"first_frame_ms", "frame_ms_p50", "frame_ms_p95", "points_per_frame_p50",
        "render_peak_rss_bytes", "gpu_cache_bytes_peak"}) {
    EXPECT_GT(bench[field].get<double>(), 0.0) << field;
  }
  EXPECT_EQ(bench["path"]["frames"], 30);
  for (const char* view : {"closeup", "street", "overview"}) {
    const nlohmann::json& figures = bench["views"][view];
    EXPECT_GT(figures["converged_psnr_db"].get<double>(), 15.0) << view;
    EXPECT_GT(figures["full_renderer_psnr_db"].get<double>(), 15.0) << view;
    EXPECT_GE(figures["converge_frames"].get<int>(), 1) << view;
  }
  // Edits in place: the store updated, not built again (the bench throws
  // otherwise); a hide and a recolour shown by the next frame, no node
  // uploaded, the store still current.
  for (const char* field :
       {"hide_ms", "recolor_ms", "commit_1m_points_ms", "insert_scan_seconds"}) {
    EXPECT_GT(bench[field].get<double>(), 0.0) << field;
  }
  for (const char* edit : {"hide", "recolor"}) {
    EXPECT_EQ(bench["edits"][edit]["uploaded_nodes"], 0) << edit;
    EXPECT_TRUE(bench["edits"][edit]["store_current"].get<bool>()) << edit;
  }
  EXPECT_GT(bench["edits"]["commit_points"].get<double>(), 0.0);
  EXPECT_EQ(bench["edits"]["delete_points"], bench["edits"]["commit_points"]);
  EXPECT_EQ(bench["edits"]["undo_delete_points"], bench["edits"]["commit_points"]);
  EXPECT_GT(bench["insert"]["points_added"].get<double>(), 0.0);
  // Five objects selected by lassos in the 3D view, each measured against
  // the truth (a smoke run's figures are not meaningful).
  ASSERT_EQ(bench["selection"].size(), 5u) << bench["selection"].dump();
  for (const auto& object : bench["selection"]) {
    EXPECT_GT(object["selection_iou"].get<double>(), 0.3) << object.dump();
    EXPECT_LE(object["selection_iou"].get<double>(), 1.0) << object.dump();
    EXPECT_GE(object["lassos"].get<int>(), 1) << object.dump();
    EXPECT_GT(object["truth_points"].get<int>(), 0) << object.dump();
  }
}

}  // namespace
}  // namespace scanbench
