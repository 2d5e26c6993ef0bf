// scanbench command line: one subcommand per pipeline stage
// (simulate → import → geometry → register → merge → harmonize → segment →
// recolor → render → export, the workbench, and info / objects / history /
// undo / redo / check over all of them).
#include <fmt/core.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <opencv2/core/utils/logger.hpp>
#include <string>
#include <string_view>

#include "app/commands.hpp"
#include "core/errors.hpp"
#include "core/memory.hpp"

namespace {

// Every failure is one line: whatever a library's text holds (newlines, a
// 5,000-character path) is cut to fit. `parts` is how many parts of
// core::kMaxMessagePart the message may hold: a FileError's three (file,
// position, problem, each already cut), a usage error or another
// library's text one.
int report_error(const char* kind, const std::string& message, int exit_code, std::size_t parts) {
  fmt::print(stderr, "scanbench: {}: {}\n", kind,
             scanbench::core::one_line(message, parts * scanbench::core::kMaxMessagePart + 16));
  return exit_code;
}

// The word the user got wrong, when there is one: an unknown command, or an
// option the command does not have. CLI11 would report the rule that broke
// next ("A subcommand is required", "project is required") instead.
std::string unknown_word(const CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return "";
  const std::string_view command = argv[1];
  const CLI::App* sub = nullptr;
  for (const CLI::App* candidate : app.get_subcommands([](const CLI::App*) { return true; })) {
    if (candidate->get_name() == command) sub = candidate;
  }
  if (sub == nullptr) {
    std::string known;
    for (const CLI::App* c : app.get_subcommands([](const CLI::App*) { return true; })) {
      known += (known.empty() ? "" : ", ") + c->get_name();
    }
    return "unknown command '" + std::string(command) + "' (commands: " + known + ")";
  }
  for (int k = 2; k < argc; ++k) {
    const std::string_view word = argv[k];
    if (word == "--") break;
    if (word.size() < 2 || word[0] != '-' || (word[1] >= '0' && word[1] <= '9')) continue;
    const std::string name(word.substr(0, word.find('=')));
    bool known = name == "-h" || name == "--help";
    for (const CLI::Option* option : sub->get_options()) {
      known = known || option->check_name(name);
    }
    if (!known) return "unknown option '" + name + "' for '" + std::string(command) + "'";
  }
  return "";
}

#ifndef SCANBENCH_WITH_BENCH
// `scanbench bench …` runs as `scanbench-bench bench …`, the same command
// line with the benches, beside this executable: the benches link PCL, whose
// libraries would cost every other command 0.1 s of dynamic linking before
// main(). Returns only when that executable is not there (a build without
// the benches: the `bench` stub then answers) or cannot start.
int run_benches(char** argv) {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  const std::filesystem::path benches = self.parent_path() / "scanbench-bench";
  if (error || !std::filesystem::exists(benches)) return -1;
  ::execv(benches.c_str(), argv);
  return report_error("error",
                      "could not start " + benches.string() + " (" + std::strerror(errno) + ")",
                      scanbench::app::kExitFailure, 1);
}
#endif

// For `bench scale`: the peak memory of this command, written as a number
// of bytes to the file SCANBENCH_PEAK_RSS_FILE names, when it names one.
// The parent cannot measure it itself: a child's maximum resident set as
// wait4 reports it includes the parent's pages it shared until exec.
void report_peak_memory() {
  const char* file = std::getenv("SCANBENCH_PEAK_RSS_FILE");
  if (file == nullptr || *file == '\0') return;
  if (const std::optional<std::uint64_t> bytes = scanbench::core::peak_resident_bytes()) {
    std::ofstream(file) << *bytes << '\n';
  }
}

int run_command(int argc, char** argv) {
  namespace sb = scanbench::app;
  // Libraries report through our errors; their own logging would print
  // before our one line (a process-wide setting: it belongs here, not in them).
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  CLI::App app{"scanbench: a workbench for terrestrial laser scans", "scanbench"};
  app.set_version_flag("--version", "scanbench 0.1.0");
  app.require_subcommand(1, 1);
  sb::add_import_command(app);
  sb::add_info_command(app);
  sb::add_geometry_command(app);
  sb::add_register_command(app);
  sb::add_merge_command(app);
  sb::add_harmonize_command(app);
  sb::add_export_command(app);
  sb::add_history_commands(app);
  sb::add_segment_command(app);
  sb::add_recolor_command(app);
  sb::add_lod_command(app);
  sb::add_render_command(app);
  sb::add_workbench_command(app);
  sb::add_objects_command(app);
  sb::add_measurements_command(app);
  sb::add_check_command(app);
  sb::add_simulate_command(app);
#ifdef SCANBENCH_WITH_BENCH
  sb::add_bench_command(app);
#else
  // Listed in --help; a call goes to scanbench-bench before parsing, or,
  // where it was not built, is refused here.
  app.add_subcommand("bench", sb::kBenchDescription)->allow_extras()->callback([] {
    throw CLI::ValidationError("bench",
                               "this scanbench was built without the benchmark suites "
                               "(configure with -DSCANBENCH_BENCH=ON)");
  });
  if (argc >= 2 && std::string_view(argv[1]) == "bench") {
    if (const int failed = run_benches(argv); failed >= 0) return failed;
  }
#endif
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help, --version
  } catch (const CLI::ParseError& e) {
    const std::string unknown = unknown_word(app, argc, argv);
    std::string message = unknown.empty() ? e.what() : unknown;
    if (message.empty()) message = "bad arguments";
    return report_error("usage",
                        scanbench::core::one_line(message, scanbench::core::kMaxMessagePart) +
                            " (see scanbench --help)",
                        sb::kExitBadInput, 1);
  } catch (const scanbench::core::InputError& e) {
    return report_error("bad input", e.what(), sb::kExitBadInput, 3);
  } catch (const scanbench::core::FileError& e) {
    return report_error("error", e.what(), sb::kExitFailure, 3);
  } catch (const std::exception& e) {
    return report_error("error", e.what(), sb::kExitFailure, 1);
  }
  return sb::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  const int code = run_command(argc, argv);
  report_peak_memory();
  return code;
}
