// Helpers shared by every test executable: fixture paths and scratch folders.
#pragma once

#include <filesystem>
#include <numbers>
#include <optional>
#include <string>

namespace scanbench::test {

// One degree [rad].
inline constexpr double kDeg = std::numbers::pi / 180.0;

// Absolute path of fixtures/<relative>. Fails the current test (ADD_FAILURE)
// when the file is missing, so a lost fixture can never pass silently.
std::filesystem::path fixture(const std::string& relative);

// A fresh, empty folder under the system temp directory, removed with its
// contents when the object dies. The name contains a space and a non-ASCII
// character so that every test exercises such paths.
class ScratchDir {
 public:
  ScratchDir();
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

// TMPDIR at a folder where no file can be made (/proc), for one scope: a
// spill file (core::SpillFile) made meanwhile is unusable.
class NoTemporaryFiles {
 public:
  NoTemporaryFiles();
  ~NoTemporaryFiles();
  NoTemporaryFiles(const NoTemporaryFiles&) = delete;
  NoTemporaryFiles& operator=(const NoTemporaryFiles&) = delete;

 private:
  std::optional<std::string> old_;
};

// Whole file contents as bytes in a string; empty string for a missing file.
std::string read_file_bytes(const std::filesystem::path& path);

}  // namespace scanbench::test
