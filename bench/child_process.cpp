#include "bench/child_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string_view>
#include <thread>

#include "core/timing.hpp"

extern char** environ;

namespace scanbench::bench {
namespace {

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

std::filesystem::path this_executable() {
  return std::filesystem::read_symlink("/proc/self/exe");
}

std::filesystem::path scanbench_beside_this() {
  std::error_code error;
  const std::filesystem::path scanbench =
      std::filesystem::read_symlink("/proc/self/exe", error).parent_path() / "scanbench";
  return !error && std::filesystem::exists(scanbench) ? scanbench : std::filesystem::path();
}

ChildRun run_process(const std::filesystem::path& program,
                     const std::vector<std::string>& arguments, const std::filesystem::path& out,
                     const std::filesystem::path& err, double timeout_s) {
  std::vector<std::string> words{program.string()};
  words.insert(words.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);
  const std::filesystem::path peak_file = out.string() == "/dev/null"
                                              ? std::filesystem::path()
                                              : std::filesystem::path(out.string() + ".peak");
  std::vector<std::string> environment{"SCANBENCH_PEAK_RSS_FILE=" + peak_file.string()};
  for (char** variable = environ; *variable != nullptr; ++variable) {
    if (!std::string_view(*variable).starts_with("SCANBENCH_PEAK_RSS_FILE="))
      environment.emplace_back(*variable);
  }
  std::vector<char*> envp;
  for (std::string& variable : environment) envp.push_back(variable.data());
  envp.push_back(nullptr);
  std::error_code ignored;
  if (!peak_file.empty()) std::filesystem::remove(peak_file, ignored);  // none from an earlier run
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&files, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const auto start = std::chrono::steady_clock::now();
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, program.c_str(), &files, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&files);
  if (spawned != 0)
    throw std::runtime_error("cannot start " + program.string() + ": " + std::strerror(spawned));
  ChildRun run;
  int status = 0;
  const int options = timeout_s > 0.0 ? WNOHANG : 0;
  for (;;) {
    const pid_t done = waitpid(pid, &status, options);
    if (done == pid) break;
    if (done < 0 && errno != EINTR)
      throw std::runtime_error(std::string("waitpid: ") + std::strerror(errno));
    if (done == 0 && core::seconds_since(start) > timeout_s && !run.timed_out) {
      ::kill(pid, SIGKILL);
      run.timed_out = true;
    }
    if (done == 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  run.seconds = core::seconds_since(start);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (!peak_file.empty()) {
    std::ifstream peak(peak_file);
    peak >> run.peak_rss_bytes;
  }
  run.out = read_text(out);
  run.err = read_text(err);
  return run;
}

ChildRun run_scanbench(const std::string& stage, const std::vector<std::string>& arguments,
                       const std::filesystem::path& dir, double timeout_s) {
  const std::filesystem::path beside = scanbench_beside_this();
  return run_process(beside.empty() ? this_executable() : beside, arguments, dir / (stage + ".out"),
                     dir / (stage + ".err"), timeout_s);
}

}  // namespace scanbench::bench
