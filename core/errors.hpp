// The two kinds of failure that reach a user, written once (docs/CONTRIBUTING.md,
// "Errors"). Programmer errors are assertions, never one of these.
//
//   InputError      bad data from outside the program: a malformed file, an
//                   impossible header, a damaged project or one from a newer
//                   version, a bad argument. The CLI exits with 2.
//   RuntimeFailure  the input was fine but the work could not be done: a full
//                   disk, an I/O error, a lock held by another process, out of
//                   memory. The CLI exits with 1.
//   Cancelled       the user asked a stage to stop (core/progress.hpp); the
//                   stage changed nothing.
//
// Whoever throws one of them has changed nothing the caller owns.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace scanbench::core {

// Where in a file the problem was found. Lines are 1-based; byte offsets are
// 0-based from the start of the file. Either may be absent when it does not
// apply (an image has no lines, a JSON key has no useful offset).
struct FilePosition {
  std::optional<std::uint64_t> line;
  std::optional<std::uint64_t> byte_offset;
  std::string detail;  // free-form position, e.g. "key \"angles.azimuth_step_deg\""
};

// What InputError and RuntimeFailure carry: the file, where in it, and the
// problem; what() is the one-line message format_input_error() makes.
// Never thrown itself: callers catch the two kinds apart.
class FileError : public std::runtime_error {
 public:
  const std::string& file() const { return file_; }
  const FilePosition& position() const { return position_; }
  const std::string& problem() const { return problem_; }

 protected:
  FileError(std::string file, FilePosition position, std::string problem);

 private:
  std::string file_;
  FilePosition position_;
  std::string problem_;
};

class InputError : public FileError {
 public:
  InputError(std::string file, FilePosition position, std::string problem)
      : FileError(std::move(file), std::move(position), std::move(problem)) {}
};

class RuntimeFailure : public FileError {
 public:
  // `file` names what could not be read or written ("" when none applies).
  RuntimeFailure(std::string file, FilePosition position, std::string problem)
      : FileError(std::move(file), std::move(position), std::move(problem)) {}
};

// Work refused because it cannot fit in the memory this process may use
// (core::check_memory): a runtime failure of this machine, not of the data.
class MemoryShortage : public RuntimeFailure {
 public:
  using RuntimeFailure::RuntimeFailure;
};

class Cancelled : public std::runtime_error {
 public:
  // `stage` names what was stopped ("geometry", "merge").
  explicit Cancelled(const std::string& stage);
};

// The longest part (file, position, problem) of a message [bytes].
inline constexpr std::size_t kMaxMessagePart = 240;

// "FILE: line 12 (byte 340): problem" — the form every message takes, on
// one line; parts longer than kMaxMessagePart are cut in the middle.
std::string format_input_error(const std::string& file, const FilePosition& position,
                               const std::string& problem);

// `text` as one line for a message or a table: control characters (C0 and
// DEL) become '?', and it is cut in the middle (between UTF-8 characters)
// to at most `limit` bytes.
std::string one_line(std::string text, std::size_t limit);

}  // namespace scanbench::core
