// A scratch folder for a bench's files, removed with everything in it, also
// when the bench throws.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace scanbench::bench {

class ScratchFolder {
 public:
  explicit ScratchFolder(const std::string& suite)
      : path_(std::filesystem::temp_directory_path() /
              ("scanbench-bench-" + suite + "-" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path_);
  }
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace scanbench::bench
