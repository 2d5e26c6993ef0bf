#include "acquisition/output_file.hpp"

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "core/errors.hpp"

namespace scanbench::acquisition {
namespace {
constexpr std::size_t kFlushBytes = 4u << 20;
}

OutputFile::OutputFile(std::filesystem::path target)
    : target_(std::move(target)), partial_(target_.string() + ".partial") {
  if (target_.empty()) throw core::InputError("", {}, "no output file given");
  std::error_code error;
  const auto status = std::filesystem::status(target_, error);
  if (std::filesystem::is_directory(status)) {
    throw core::InputError(target_.string(), {}, "is a directory; give the output a file name");
  }
  if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    throw core::InputError(target_.string(), {},
                           "is not a regular file (a device or a pipe); exports write files");
  }
  file_ = std::fopen(partial_.c_str(), "wb");
  if (file_ == nullptr) fail("cannot create");
  buffer_.reserve(kFlushBytes + 4096);
}

OutputFile::~OutputFile() {
  if (file_ != nullptr) std::fclose(file_);
  if (file_ != nullptr || closed_) {
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

void OutputFile::close() {
  if (file_ == nullptr) return;
  flush();
  const int closed = std::fclose(file_);
  file_ = nullptr;
  closed_ = true;
  if (closed != 0) fail("cannot write");
}

void OutputFile::commit() {
  close();
  std::error_code error;
  std::filesystem::rename(partial_, target_, error);
  if (error) {
    const std::string problem = error.message();
    throw std::runtime_error(target_.string() + ": cannot replace: " + problem);
  }
  closed_ = false;  // renamed: nothing left to remove
}

void OutputFile::fail(const std::string& what) const {
  throw std::runtime_error(target_.string() + ": " + what + ": " + std::strerror(errno));
}

}  // namespace scanbench::acquisition
