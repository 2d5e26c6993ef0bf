// scanbench command line: one subcommand per pipeline stage
// (simulate → import → geometry → register → merge → info → export, and
// history / undo / redo over all of them;
// segment and render join as their stages land).
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <exception>

#include "app/commands.hpp"
#include "core/errors.hpp"

namespace {

int report_error(const char* kind, const char* message, int exit_code) {
  fmt::print(stderr, "scanbench: {}: {}\n", kind, message);
  return exit_code;
}

}  // namespace

int main(int argc, char** argv) {
  namespace sb = scanbench::app;
  CLI::App app{"scanbench: a workbench for terrestrial laser scans", "scanbench"};
  app.set_version_flag("--version", "scanbench 0.1.0");
  app.require_subcommand(1, 1);
  sb::add_import_command(app);
  sb::add_info_command(app);
  sb::add_geometry_command(app);
  sb::add_register_command(app);
  sb::add_merge_command(app);
  sb::add_export_command(app);
  sb::add_history_commands(app);
  sb::add_simulate_command(app);
#ifdef SCANBENCH_WITH_BENCH
  sb::add_bench_command(app);
#else
  app.add_subcommand("bench", "Not in this build (configured with -DSCANBENCH_BENCH=OFF)")
      ->allow_extras()
      ->callback([] {
        throw CLI::ValidationError("bench",
                                   "this scanbench was built without the benchmark "
                                   "suites (-DSCANBENCH_BENCH=OFF)");
      });
#endif
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help, --version
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return sb::kExitBadInput;
  } catch (const scanbench::core::InputError& e) {
    return report_error("bad input", e.what(), sb::kExitBadInput);
  } catch (const std::exception& e) {
    return report_error("error", e.what(), sb::kExitFailure);
  }
  return sb::kExitOk;
}
