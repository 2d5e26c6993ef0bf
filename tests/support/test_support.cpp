#include "support/test_support.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace scanbench::test {

std::filesystem::path fixture(const std::string& relative) {
  const std::filesystem::path path = std::filesystem::path(SCANBENCH_FIXTURES_DIR) / relative;
  if (!std::filesystem::exists(path)) ADD_FAILURE() << "missing fixture: " << path;
  return path;
}

ScratchDir::ScratchDir() {
  static std::atomic<int> counter{0};
  const std::string name =
      "scanbench test é " + std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1));
  path_ = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(path_);
  std::filesystem::create_directories(path_);
}

ScratchDir::~ScratchDir() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

std::string read_file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

NoTemporaryFiles::NoTemporaryFiles() {
  if (const char* old = std::getenv("TMPDIR")) old_ = old;
  ::setenv("TMPDIR", "/proc", 1);
}

NoTemporaryFiles::~NoTemporaryFiles() {
  if (old_) {
    ::setenv("TMPDIR", old_->c_str(), 1);
  } else {
    ::unsetenv("TMPDIR");
  }
}

}  // namespace scanbench::test
