#include "core/spill_file.hpp"

#include <fcntl.h>
#include <linux/magic.h>
#include <sys/vfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "core/errors.hpp"

namespace scanbench::core {

namespace {

// True when `folder` is on a file system in memory.
bool in_memory(const std::filesystem::path& folder) {
  struct statfs info {};
  return ::statfs(folder.c_str(), &info) == 0 && info.f_type == TMPFS_MAGIC;
}

// The temporary folder, or /var/tmp where that one is in memory and
// /var/tmp is not.
std::filesystem::path spill_folder() {
  std::error_code error;
  std::filesystem::path folder = std::filesystem::temp_directory_path(error);
  if (error) folder = "/tmp";
  const std::filesystem::path var_tmp = "/var/tmp";
  if (in_memory(folder) && std::filesystem::is_directory(var_tmp, error) && !in_memory(var_tmp))
    return var_tmp;
  return folder;
}

}  // namespace

SpillFile::SpillFile() : folder_(spill_folder()) {
  fd_ = ::open(folder_.c_str(), O_TMPFILE | O_RDWR | O_CLOEXEC, 0600);
  if (fd_ >= 0) return;
  std::string name = (folder_ / "scanbench-spill-XXXXXX").string();
  fd_ = ::mkostemp(name.data(), O_CLOEXEC);
  if (fd_ >= 0) ::unlink(name.c_str());
}

SpillFile::~SpillFile() {
  if (fd_ >= 0) ::close(fd_);
}

std::optional<SpillFile::Extent> SpillFile::put(const void* data, std::size_t bytes) {
  if (!usable()) return std::nullopt;
  const auto* from = static_cast<const std::uint8_t*>(data);
  std::size_t done = 0;
  while (done < bytes) {
    const ssize_t wrote = ::pwrite(fd_, from + done, bytes - done, static_cast<off_t>(end_ + done));
    if (wrote <= 0) {
      failed_ = true;
      return std::nullopt;
    }
    done += static_cast<std::size_t>(wrote);
  }
  const Extent extent{end_, bytes};
  end_ += bytes;
  return extent;
}

void SpillFile::release(const Extent& extent) {
  if (fd_ < 0 || extent.bytes == 0) return;
  // Best effort: a file system without holes keeps the space until the
  // file is closed.
  (void)::fallocate(fd_, FALLOC_FL_PUNCH_HOLE | FALLOC_FL_KEEP_SIZE,
                    static_cast<off_t>(extent.offset), static_cast<off_t>(extent.bytes));
}

void SpillFile::get(const Extent& extent, void* data) const {
  auto* to = static_cast<std::uint8_t*>(data);
  std::size_t done = 0;
  while (done < extent.bytes) {
    const ssize_t got =
        ::pread(fd_, to + done, extent.bytes - done, static_cast<off_t>(extent.offset + done));
    if (got < 0) {
      throw RuntimeFailure(
          folder_.string(), {},
          std::string("cannot read back the data parked in a temporary file here: ") +
              std::strerror(errno));
    }
    if (got == 0) {
      throw RuntimeFailure(folder_.string(), {},
                           "a temporary file here holding parked data ends early");
    }
    done += static_cast<std::size_t>(got);
  }
}

}  // namespace scanbench::core
