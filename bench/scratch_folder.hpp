// A scratch folder for a bench's files, removed with everything in it, also
// when the bench throws.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

#include "core/scratch_folder.hpp"

namespace scanbench::bench {

// temp_directory_path() / "scanbench-bench-SUITE-PID".
class ScratchFolder : public core::ScratchFolder {
 public:
  explicit ScratchFolder(const std::string& suite)
      : core::ScratchFolder(std::filesystem::temp_directory_path(),
                            "scanbench-bench-" + suite + "-" + std::to_string(::getpid())) {}
};

}  // namespace scanbench::bench
