#include "core/errors.hpp"

#include <sstream>

#include "core/text.hpp"

namespace scanbench::core {

// A 5,000-character file name or a 200 KB token must not flood the terminal.
std::string one_line(std::string text, std::size_t limit) {
  for (char& c : text) {
    if (is_control_character(c)) c = '?';  // one line, whatever a name holds
  }
  if (text.size() <= limit) return text;
  const std::size_t half = limit / 2;
  std::size_t head = half, tail = text.size() - half;
  // Cut between UTF-8 characters, never inside one.
  while (head > 0 && (static_cast<unsigned char>(text[head]) & 0xC0) == 0x80) --head;
  while (tail < text.size() && (static_cast<unsigned char>(text[tail]) & 0xC0) == 0x80) ++tail;
  return text.substr(0, head) + "…" + text.substr(tail);
}

std::string format_input_error(const std::string& file_name, const FilePosition& position,
                               const std::string& problem_text) {
  const std::string file = one_line(file_name, kMaxMessagePart);
  const std::string problem = one_line(problem_text, kMaxMessagePart);
  std::ostringstream out;
  out << file;
  std::string where;
  if (position.line) where += "line " + std::to_string(*position.line);
  if (position.byte_offset) {
    where += where.empty() ? "" : " ";
    where += "(byte " + std::to_string(*position.byte_offset) + ")";
  }
  if (!position.detail.empty()) {
    where += where.empty() ? "" : ", ";
    where += one_line(position.detail, kMaxMessagePart);
  }
  if (!where.empty()) out << (file.empty() ? "" : ": ") << where;
  out << (file.empty() && where.empty() ? "" : ": ") << problem;
  return out.str();
}

FileError::FileError(std::string file, FilePosition position, std::string problem)
    : std::runtime_error(format_input_error(file, position, problem)),
      file_(std::move(file)),
      position_(std::move(position)),
      problem_(std::move(problem)) {}

Cancelled::Cancelled(const std::string& stage)
    : std::runtime_error(stage + " cancelled; nothing was changed") {}

}  // namespace scanbench::core
