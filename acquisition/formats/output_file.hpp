// All-or-nothing file output for the exporters: bytes go to a temporary file
// beside the target, which replaces the target only on commit(). A failed or
// interrupted export therefore never leaves a half-written file behind.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace scanbench::acquisition {

class OutputFile {
 public:
  // Creates "<target>.partial-<pid>", a new file of its own (never through a
  // symlink, never shared with another export to the same target), after
  // removing what killed runs of this export left beside the target (their
  // processes are gone). Throws core::InputError when `target` is empty, a
  // directory, an existing file that is not a regular file, a scanbench
  // project (of any name), or in a folder that does not exist; core::RuntimeFailure naming the file
  // when it cannot be created otherwise.
  explicit OutputFile(std::filesystem::path target);
  // Removes the temporary file unless commit() succeeded.
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  // Buffered; throws core::RuntimeFailure on a write error (disk full).
  void write(std::string_view bytes);
  // Flushes the temporary file to the disk (fsync) and closes it; throws
  // core::RuntimeFailure on a write error. Outputs that belong together (a
  // triplet) close all before any replaces its target, so a full disk leaves
  // none of them behind.
  void close();
  // close() when still open, then renames onto the target; throws
  // core::RuntimeFailure when the rename fails.
  void commit();

  // Overwrites bytes already written, at `offset` from the file's start
  // (a header whose fields are known only at the end); later writes append
  // again. Asserts the range lies within what was written; throws as write().
  void rewrite(std::uint64_t offset, std::string_view bytes);

  // Appends to an internal buffer that is flushed in large blocks: the text
  // exporters format numbers straight into it.
  std::string& buffer() { return buffer_; }
  void flush_if_full();

 private:
  void flush();
  [[noreturn]] void fail(const std::string& what) const;

  std::filesystem::path target_;
  std::filesystem::path partial_;
  std::FILE* file_ = nullptr;
  bool closed_ = false;  // closed, not yet renamed: the partial file is still there
  std::string buffer_;
};

// Writes files that belong together (a triplet, a picture and its object
// ids), each through an OutputFile: all are on the disk beside their
// targets before any replaces its target, in the order given (a sidecar
// last). A failure leaves the old files (or none) behind. Throws as
// OutputFile.
void write_files_together(const std::vector<std::pair<std::filesystem::path, std::string>>& files);

}  // namespace scanbench::acquisition
