// All-or-nothing file output for the exporters: bytes go to a temporary file
// beside the target, which replaces the target only on commit(). A failed or
// interrupted export therefore never leaves a half-written file behind.
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

namespace scanbench::acquisition {

class OutputFile {
 public:
  // Creates "<target>.partial"; throws std::runtime_error naming the file
  // when it cannot be created.
  explicit OutputFile(std::filesystem::path target);
  // Removes the temporary file unless commit() succeeded.
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  // Buffered; throws std::runtime_error on a write error (disk full).
  void write(std::string_view bytes);
  // Flushes, closes and renames onto the target.
  void commit();

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
  std::string buffer_;
};

}  // namespace scanbench::acquisition
