// Runs the scanbench executable for the end-to-end tests: arguments are
// shell-quoted, stdout and stderr captured through files in a scratch folder.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "support/test_support.hpp"

namespace scanbench::test {

struct CliResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

inline std::string shell_quote(const std::string& arg) {
  std::string quoted = "'";
  for (const char c : arg) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

// `prefix`, when given, runs the executable under another command (a
// virtual display: "xvfb-run -a …"); it is passed to the shell as it is.
inline CliResult run_cli(const ScratchDir& dir, const std::vector<std::string>& args,
                         const std::string& prefix = "") {
  std::string command = prefix.empty() ? std::string() : prefix + " ";
  command += shell_quote(SCANBENCH_BINARY);
  for (const std::string& arg : args) {
    command += ' ';  // appended apart: GCC 12 warns falsely on " " + std::string&& at -O3
    command += shell_quote(arg);
  }
  const std::filesystem::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  command += " >" + shell_quote(out.string()) + " 2>" + shell_quote(err.string());
  const int status = std::system(command.c_str());
  CliResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = read_file_bytes(out);
  result.err = read_file_bytes(err);
  return result;
}

// Runs `shell` (with $SCANBENCH set to the executable) under /bin/sh.
inline CliResult run_shell(const ScratchDir& dir, const std::string& shell) {
  const std::filesystem::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string command = "SCANBENCH=" + shell_quote(SCANBENCH_BINARY) + " /bin/sh -c " +
                              shell_quote(shell) + " >" + shell_quote(out.string()) + " 2>" +
                              shell_quote(err.string());
  const int status = std::system(command.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file_bytes(out), read_file_bytes(err)};
}

// A project holding the tiny colour scan, and what `info --json` says of it.
inline std::string make_project(const ScratchDir& dir, const std::filesystem::path& project) {
  EXPECT_EQ(run_cli(dir, {"import", project.string(), fixture("good/ptx/tiny_color.ptx").string()})
                .exit_code,
            0);
  return run_cli(dir, {"info", project.string(), "--json"}).out;
}

// One line on stderr, "scanbench: …", holding `words`, and `exit_code`.
inline void expect_one_line_error(const CliResult& result, int exit_code,
                                  const std::string& words) {
  EXPECT_EQ(result.exit_code, exit_code) << result.err;
  EXPECT_EQ(result.err.rfind("scanbench: ", 0), 0u) << result.err;
  EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
  EXPECT_NE(result.err.find(words), std::string::npos) << result.err;
}

}  // namespace scanbench::test
