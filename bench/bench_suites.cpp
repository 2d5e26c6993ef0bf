#include "bench/bench_suites.hpp"

#include <cassert>

#include "bench/bench_color.hpp"
#include "bench/bench_geometry.hpp"
#include "bench/bench_io.hpp"
#include "bench/bench_lod.hpp"
#include "bench/bench_merge.hpp"
#include "bench/bench_registration.hpp"
#include "bench/bench_render.hpp"
#include "bench/bench_scale.hpp"
#include "bench/bench_segmentation.hpp"

namespace scanbench::bench {

std::vector<std::string> suite_names() {
  return {"io",     "geometry", "registration", "merge", "segmentation",
          "render", "color",    "scale",        "lod"};
}

nlohmann::json run_suite(const std::string& name, const BenchOptions& options) {
  if (name == "io") return run_io_bench(options);
  if (name == "geometry") return run_geometry_bench(options);
  if (name == "registration") return run_registration_bench(options);
  if (name == "merge") return run_merge_bench(options);
  if (name == "segmentation") return run_segmentation_bench(options);
  if (name == "render") return run_render_bench(options);
  if (name == "color") return run_color_bench(options);
  if (name == "scale") return run_scale_bench(options);
  if (name == "lod") return run_lod_bench(options);
  assert(false && "unknown bench suite");
  return {};
}

}  // namespace scanbench::bench
