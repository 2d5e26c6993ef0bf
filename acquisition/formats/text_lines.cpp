#include "acquisition/formats/text_lines.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>

namespace scanbench::acquisition {
namespace {

constexpr std::size_t kChunkBytes = 4u << 20;
constexpr std::size_t kMaxLineBytes = 64u << 10;  // a PTX line is < 100 bytes

bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r';
}

}  // namespace

TextLineReader::TextLineReader(const std::filesystem::path& path) : file_name_(path.string()) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (std::filesystem::is_directory(status)) {
    throw core::InputError(file_name_, {}, "is a directory, not a file");
  }
  // A pipe with no writer would block the read forever, and a device has no
  // end: only regular files are scan files.
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    throw core::InputError(file_name_, {}, "is not a regular file (a pipe or a device)");
  }
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) {
    throw core::InputError(file_name_, {}, std::string("cannot open: ") + std::strerror(errno));
  }
  file_size_ = std::filesystem::file_size(path, error);
  // A small file gets a buffer its size, not 4 MB (opening many small files,
  // as the fuzzer does, then costs little).
  buffer_.resize(
      std::clamp<std::size_t>(static_cast<std::size_t>(file_size_) + 1, 4096, kChunkBytes));
}

TextLineReader::~TextLineReader() {
  if (file_ != nullptr) std::fclose(file_);
}

bool TextLineReader::refill() {
  if (eof_) return false;
  if (begin_ > 0) {  // keep the partial line, move it to the front
    std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  if (end_ == buffer_.size()) {
    if (buffer_.size() >= kMaxLineBytes + kChunkBytes) fail("line is too long");
    buffer_.resize(buffer_.size() + kChunkBytes);
  }
  const std::size_t got = std::fread(buffer_.data() + end_, 1, buffer_.size() - end_, file_);
  if (got == 0) {
    if (std::ferror(file_)) fail("read error");
    eof_ = true;
    return false;
  }
  end_ += got;
  return true;
}

bool TextLineReader::next(std::string_view& line) {
  std::size_t scanned = begin_;
  for (;;) {
    const void* hit = std::memchr(buffer_.data() + scanned, '\n', end_ - scanned);
    if (hit != nullptr) {
      const auto newline = static_cast<std::size_t>(static_cast<const char*>(hit) - buffer_.data());
      std::size_t stop = newline;
      if (stop > begin_ && buffer_[stop - 1] == '\r') --stop;
      line = std::string_view(buffer_.data() + begin_, stop - begin_);
      line_offset_ = consumed_;
      consumed_ += newline + 1 - begin_;
      begin_ = newline + 1;
      ++line_number_;
      return true;
    }
    const std::size_t pending = end_ - begin_;
    if (!refill()) break;
    scanned = begin_ + pending;
  }
  if (begin_ == end_) return false;
  // Last line without a terminator.
  std::size_t stop = end_;
  if (buffer_[stop - 1] == '\r') --stop;
  line = std::string_view(buffer_.data() + begin_, stop - begin_);
  line_offset_ = consumed_;
  consumed_ += end_ - begin_;
  begin_ = end_;
  ++line_number_;
  return true;
}

void TextLineReader::fail(const std::string& problem) const {
  throw core::InputError(file_name_, {line_number_, line_offset_, {}}, problem);
}

int parse_numbers(std::string_view line, std::span<double> out) {
  const char* p = line.data();
  const char* const end = p + line.size();
  int fields = 0;
  for (;;) {
    while (p < end && is_blank(*p)) ++p;
    if (p == end) return fields;
    const char* field_end = p;
    while (field_end < end && !is_blank(*field_end)) ++field_end;
    if (static_cast<std::size_t>(fields) < out.size()) {
      double value = 0.0;
      const auto [stop, error] = std::from_chars(p, field_end, value);
      if (error != std::errc() || stop != field_end || !std::isfinite(value)) return -1;
      out[fields] = value;
    }
    ++fields;
    p = field_end;
  }
}

}  // namespace scanbench::acquisition
