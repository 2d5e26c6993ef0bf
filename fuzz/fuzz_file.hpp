// The fuzz targets' common part: readers take paths, so each input is
// written to a file in a RAM-backed folder and handed over by name.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>

#include "core/errors.hpp"
#include "core/scratch_folder.hpp"

namespace scanbench::fuzz {

// A folder of this process in /dev/shm (or the temporary folder), removed
// when the process exits normally.
inline const std::filesystem::path& work_folder() {
  static const core::ScratchFolder folder(std::filesystem::exists("/dev/shm")
                                              ? std::filesystem::path("/dev/shm")
                                              : std::filesystem::temp_directory_path(),
                                          "scanbench-fuzz-" + std::to_string(::getpid()));
  return folder.path();
}

// Writes `data` to work_folder() / name and returns the path.
inline std::filesystem::path write_input(const std::uint8_t* data, std::size_t size,
                                         const std::string& name) {
  const std::filesystem::path path = work_folder() / name;
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (file == nullptr) std::abort();
  if (size > 0 && std::fwrite(data, 1, size, file) != size) std::abort();
  std::fclose(file);
  return path;
}

// Runs `read`. Bad input must be refused as such (core::InputError), and
// so may work that does not fit in memory (core::MemoryShortage); any other
// failure reading a file from RAM, a RuntimeFailure included, is a finding.
template <typename Read>
void expect_refusal_or_success(Read&& read) {
  try {
    read();
  } catch (const core::InputError&) {
  } catch (const core::MemoryShortage&) {
  } catch (const core::RuntimeFailure& failure) {
    std::fprintf(stderr, "finding: a runtime failure for bad input: %s\n", failure.what());
    std::abort();
  }
}

}  // namespace scanbench::fuzz
