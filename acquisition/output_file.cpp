#include "acquisition/output_file.hpp"

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace scanbench::acquisition {
namespace {
constexpr std::size_t kFlushBytes = 4u << 20;
}

OutputFile::OutputFile(std::filesystem::path target)
    : target_(std::move(target)), partial_(target_.string() + ".partial") {
  file_ = std::fopen(partial_.c_str(), "wb");
  if (file_ == nullptr) fail("cannot create");
  buffer_.reserve(kFlushBytes + 4096);
}

OutputFile::~OutputFile() {
  if (file_ != nullptr) {
    std::fclose(file_);
    std::error_code ignored;
    std::filesystem::remove(partial_, ignored);
  }
}

void OutputFile::write(std::string_view bytes) {
  buffer_.append(bytes);
  flush_if_full();
}

void OutputFile::flush_if_full() {
  if (buffer_.size() >= kFlushBytes) flush();
}

void OutputFile::flush() {
  if (!buffer_.empty() && std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) {
    fail("cannot write");
  }
  buffer_.clear();
}

void OutputFile::commit() {
  flush();
  const int closed = std::fclose(file_);
  file_ = nullptr;
  std::error_code error;
  if (closed != 0) {
    std::filesystem::remove(partial_, error);
    fail("cannot write");
  }
  std::filesystem::rename(partial_, target_, error);
  if (error) {
    std::filesystem::remove(partial_, error);
    throw std::runtime_error(target_.string() + ": cannot replace: " + error.message());
  }
}

void OutputFile::fail(const std::string& what) const {
  throw std::runtime_error(target_.string() + ": " + what + ": " + std::strerror(errno));
}

}  // namespace scanbench::acquisition
