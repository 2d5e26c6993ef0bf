#include "core/project_file.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <vector>

namespace scanbench::core {
namespace {

// The descriptors this process has open on the file of `status`, from
// /proc/self/fd; none on systems without it.
std::vector<int> open_already(const struct stat& status) {
  std::vector<int> found;
  DIR* const folder = ::opendir("/proc/self/fd");
  if (folder == nullptr) return found;
  const int own = ::dirfd(folder);
  while (const dirent* entry = ::readdir(folder)) {
    char* end = nullptr;
    const long fd = std::strtol(entry->d_name, &end, 10);
    if (end == entry->d_name || *end != '\0' || fd == own) continue;
    struct stat other {};
    if (::fstat(static_cast<int>(fd), &other) == 0 && other.st_dev == status.st_dev &&
        other.st_ino == status.st_ino) {
      found.push_back(static_cast<int>(fd));
    }
  }
  ::closedir(folder);
  return found;
}

}  // namespace

bool is_project_file(const std::filesystem::path& file) {
  struct stat status {};
  if (::stat(file.c_str(), &status) != 0 || !S_ISREG(status.st_mode)) return false;
  std::array<unsigned char, 100> header{};
  // A file this process has open (a project an SQLite connection holds) is
  // read through that descriptor: closing one of our own would drop the
  // POSIX locks the connection holds on it, which belong to the process.
  // (An SQLite connection's descriptors are readable; only where none of
  // this process's is, a descriptor of our own is opened and closed.)
  ssize_t got = -1;
  for (const int held : open_already(status)) {
    got = ::pread(held, header.data(), header.size(), 0);
    if (got >= 0) break;
  }
  if (got < 0) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return false;
    got = ::pread(fd, header.data(), header.size(), 0);
    ::close(fd);
  }
  if (got != static_cast<ssize_t>(header.size())) return false;
  constexpr char kMagic[16] = "SQLite format 3";  // with its terminating NUL: 16 bytes
  const std::uint32_t application_id = (std::uint32_t{header[68]} << 24) |
                                       (std::uint32_t{header[69]} << 16) |
                                       (std::uint32_t{header[70]} << 8) | std::uint32_t{header[71]};
  return std::equal(kMagic, kMagic + 16, header.begin()) && application_id == kProjectApplicationId;
}

}  // namespace scanbench::core
