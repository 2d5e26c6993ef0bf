// Streaming line access and number parsing for the ASCII formats (PTX).
//
// The file is read in large chunks, never whole, so a 10 GB PTX costs a few
// megabytes of memory. Every line knows its 1-based number and byte offset for
// error messages. Numbers are parsed with std::from_chars: locale-free, no
// allocation, and fast enough for ≥ 100 MB/s on one core.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/errors.hpp"

namespace scanbench::acquisition {

class TextLineReader {
 public:
  // Opens `path`; throws InputError when it cannot be opened, is a directory,
  // or is not a regular file (a pipe would block, a device never ends).
  explicit TextLineReader(const std::filesystem::path& path);
  ~TextLineReader();
  TextLineReader(const TextLineReader&) = delete;
  TextLineReader& operator=(const TextLineReader&) = delete;

  // Stores the next line, without "\n" or "\r\n", in `line` (valid until the
  // next call) and returns true; returns false at the end of the file.
  bool next(std::string_view& line);

  std::uint64_t line_number() const { return line_number_; }  // of the last line returned
  std::uint64_t line_offset() const { return line_offset_; }  // its first byte
  std::uint64_t file_size() const { return file_size_; }
  std::uint64_t bytes_consumed() const { return consumed_; }  // just past the last line
  const std::string& file_name() const { return file_name_; }

  // An InputError at the last line returned.
  [[noreturn]] void fail(const std::string& problem) const;

 private:
  bool refill();

  std::FILE* file_ = nullptr;
  std::string file_name_;
  std::uint64_t file_size_ = 0;
  std::vector<char> buffer_;
  std::size_t begin_ = 0;  // first unread byte in buffer_
  std::size_t end_ = 0;    // one past the last valid byte in buffer_
  bool eof_ = false;
  std::uint64_t line_number_ = 0;
  std::uint64_t line_offset_ = 0;
  std::uint64_t consumed_ = 0;
};

// Splits `line` at blanks (spaces, tabs) and parses up to out.size() numbers.
// Returns how many fields the line has (which may exceed out.size(); the extra
// ones are not parsed), or -1 when a parsed field is not a finite number
// ("nan", "inf", "1.2.3", "abc" are all refused).
int parse_numbers(std::string_view line, std::span<double> out);

}  // namespace scanbench::acquisition
