// An unnamed file on disk where a stage parks data it will read again,
// instead of holding it in memory: the kernel's page cache keeps what
// fits, and the rest waits on the disk. In the temporary folder (TMPDIR,
// else /tmp), or in /var/tmp where that folder is in memory (tmpfs, as
// Debian 13's /tmp: parked data would then take memory after all).
// O_TMPFILE where the file system has it (the file has no name and goes
// when it is closed or the process dies), else a file made by mkstemp and
// unlinked at once. Best effort: where no such file can be made, or once a
// write fails (a full disk), put() says so and the caller keeps the data
// another way.
#pragma once

#include <cassert>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <vector>

namespace scanbench::core {

class SpillFile {
 public:
  // Where in the file a put() went.
  struct Extent {
    std::uint64_t offset = 0;
    std::uint64_t bytes = 0;
  };

  // Opens the file; usable() says whether that worked.
  SpillFile();
  ~SpillFile();
  SpillFile(const SpillFile&) = delete;
  SpillFile& operator=(const SpillFile&) = delete;

  // False once the file cannot be made or has failed a write.
  bool usable() const { return fd_ >= 0 && !failed_; }

  // Appends `bytes` bytes at `data`; none when the file cannot take them
  // (the file is then unusable from here on; what it took stays readable).
  std::optional<Extent> put(const void* data, std::size_t bytes);

  // Reads `extent` back into `data` (extent.bytes long). Throws
  // core::RuntimeFailure naming the file's folder when it cannot.
  void get(const Extent& extent, void* data) const;

  // Gives the disk space of `extent`, which will not be read again, back to
  // the file system (a hole in the file) where it can; the file's size and
  // the other extents stay. So a file that many puts go through takes only
  // what is still to be read.
  void release(const Extent& extent);

  // Puts each vector's elements (plain data, copied byte for byte) in turn: their
  // extents, in order; none when the file cannot take them all (what it
  // took of them is released).
  template <typename... Vectors>
  std::optional<std::vector<Extent>> put_vectors(const Vectors&... vectors) {
    std::vector<Extent> extents;
    const auto put_one = [&](const auto& v) {
      const std::optional<Extent> extent = put(v.data(), v.size() * sizeof(v[0]));
      if (extent) extents.push_back(*extent);
      return extent.has_value();
    };
    if ((put_one(vectors) && ...)) return extents;
    for (const Extent& extent : extents) release(extent);
    return std::nullopt;
  }

  // Reads what put_vectors() put, at `extents`, back into `vectors` (of the
  // same types, in the same order), each resized to its extent. Throws as
  // get().
  template <typename... Vectors>
  void get_vectors(std::span<const Extent> extents, Vectors&... vectors) const {
    assert(extents.size() == sizeof...(Vectors) && "one extent a vector");
    std::size_t k = 0;
    const auto get_one = [&](auto& v) {
      const Extent& extent = extents[k++];
      assert(extent.bytes % sizeof(v[0]) == 0 && "the extent of a vector of this type");
      v.resize(extent.bytes / sizeof(v[0]));
      get(extent, v.data());
    };
    (get_one(vectors), ...);
  }

  // The bytes put so far.
  std::uint64_t size() const { return end_; }
  // The folder the file is in (empty when there is none).
  const std::filesystem::path& folder() const { return folder_; }

 private:
  int fd_ = -1;
  std::filesystem::path folder_;
  std::uint64_t end_ = 0;
  bool failed_ = false;
};

}  // namespace scanbench::core
