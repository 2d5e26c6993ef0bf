// What marks a file as a scanbench project, whatever its name or schema
// version: an SQLite database whose application id is ours. Here, below
// every module, so that no output of any module ever replaces a project.
#pragma once

#include <cstdint>
#include <filesystem>

namespace scanbench::core {

// "SBNC", in the SQLite header's application_id field.
inline constexpr std::uint32_t kProjectApplicationId = 0x53424E43;

// True when `file` is a regular file that starts like a scanbench project:
// the SQLite header with kProjectApplicationId (bytes 68 to 71, big-endian).
// Reads the 100-byte header only, through a descriptor this process has
// open on the file where there is one, so that it does not drop the POSIX
// locks of an SQLite connection holding the file (a connection another
// thread opens meanwhile is not covered); false for anything unreadable.
bool is_project_file(const std::filesystem::path& file);

}  // namespace scanbench::core
