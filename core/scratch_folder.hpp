// A folder made for one owner's files and removed, with everything in it,
// when the owner ends, also when it throws: a bench's or a fuzz target's
// scratch space.
#pragma once

#include <filesystem>
#include <string>
#include <system_error>

namespace scanbench::core {

class ScratchFolder {
 public:
  // Makes `parent` / `name` (and `parent` if need be). Throws
  // std::filesystem::filesystem_error when it cannot.
  ScratchFolder(const std::filesystem::path& parent, const std::string& name)
      : path_(parent / name) {
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

}  // namespace scanbench::core
