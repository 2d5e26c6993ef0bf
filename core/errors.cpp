#include "core/errors.hpp"

#include <sstream>

namespace scanbench::core {

std::string format_input_error(const std::string& file, const FilePosition& position,
                               const std::string& problem) {
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
    where += position.detail;
  }
  if (!where.empty()) out << (file.empty() ? "" : ": ") << where;
  out << (file.empty() && where.empty() ? "" : ": ") << problem;
  return out.str();
}

InputError::InputError(std::string file, FilePosition position, std::string problem)
    : std::runtime_error(format_input_error(file, position, problem)),
      file_(std::move(file)),
      position_(std::move(position)),
      problem_(std::move(problem)) {}

RuntimeFailure::RuntimeFailure(std::string file, FilePosition position, std::string problem)
    : std::runtime_error(format_input_error(file, position, problem)),
      file_(std::move(file)),
      position_(std::move(position)),
      problem_(std::move(problem)) {}

Cancelled::Cancelled(const std::string& stage)
    : std::runtime_error(stage + " cancelled; nothing was changed") {}

}  // namespace scanbench::core
