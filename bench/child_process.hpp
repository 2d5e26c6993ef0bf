// Running a command in a process of its own: what a user waits for, and,
// for one stage of scanbench, its peak memory as the kernel counts it for
// that stage alone.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace scanbench::bench {

struct ChildRun {
  int exit_code = 0;     // -1 when killed by a signal
  bool timed_out = false;  // killed for running past its time
  double seconds = 0.0;  // from spawning to exit
  // The kernel's high-water mark of the program's resident memory (VmHWM),
  // as scanbench reports it through SCANBENCH_PEAK_RSS_FILE; 0 for other
  // programs. Not wait4's maximum resident set: after posix_spawn (vfork)
  // that includes the parent's resident pages, which the child shared
  // until it called exec.
  std::uint64_t peak_rss_bytes = 0;
  std::string out;  // standard output
  std::string err;  // standard error
};

// The running executable (/proc/self/exe).
std::filesystem::path this_executable();

// The `scanbench` executable beside this one (what users run, without the
// bench's peers linked in), or an empty path when there is none.
std::filesystem::path scanbench_beside_this();

// Runs `program` with `arguments` (argv[1..]), its standard output and
// error written to the files `out` and `err` (read back into the result;
// /dev/null reads back empty), and waits for it, at most `timeout_s`
// seconds (0: as long as it runs), then kills it. Throws std::runtime_error
// when the process cannot be started.
ChildRun run_process(const std::filesystem::path& program,
                     const std::vector<std::string>& arguments, const std::filesystem::path& out,
                     const std::filesystem::path& err, double timeout_s = 0.0);

// Runs `scanbench` (the one beside this executable, else this one) with
// `arguments`, its output and errors in `dir`/STAGE.out and STAGE.err, as
// run_process does.
ChildRun run_scanbench(const std::string& stage, const std::vector<std::string>& arguments,
                       const std::filesystem::path& dir, double timeout_s = 0.0);

}  // namespace scanbench::bench
