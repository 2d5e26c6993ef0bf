// Bad data from outside the program: a malformed file, an impossible header, a
// project from a newer version. Every reader throws this (and only this) for
// bad input, before it changes anything the caller owns. Programmer errors
// are assertions, never InputError (docs/CONTRIBUTING.md, "Errors").
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

namespace scanbench::acquisition {

// Where in a file the problem was found. Lines are 1-based; byte offsets are
// 0-based from the start of the file. Either may be absent when it does not
// apply (an image has no lines, a JSON key has no useful offset).
struct FilePosition {
  std::optional<std::uint64_t> line;
  std::optional<std::uint64_t> byte_offset;
  std::string detail;  // free-form position, e.g. "key \"angles.azimuth_step_deg\""
};

class InputError : public std::runtime_error {
 public:
  InputError(std::string file, FilePosition position, std::string problem);

  const std::string& file() const { return file_; }
  const FilePosition& position() const { return position_; }
  const std::string& problem() const { return problem_; }

 private:
  std::string file_;
  FilePosition position_;
  std::string problem_;
};

// "FILE:line 12 (byte 340): problem" — the form every message takes.
std::string format_input_error(const std::string& file, const FilePosition& position,
                               const std::string& problem);

}  // namespace scanbench::acquisition
