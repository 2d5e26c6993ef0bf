#include "acquisition/formats/output_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cassert>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <memory>

#include "core/errors.hpp"
#include "core/project_file.hpp"

namespace scanbench::acquisition {
namespace {

constexpr std::size_t kFlushBytes = 4u << 20;
constexpr std::string_view kPartial = ".partial-";

// Removes "<target>.partial-<pid>" regular files whose process is gone:
// what a killed run of an export to the same target left.
void remove_abandoned_partials(const std::filesystem::path& target) {
  const std::filesystem::path folder =
      target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  const std::string prefix = target.filename().string() + std::string(kPartial);
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    pid_t pid = 0;
    const char* digits = name.data() + prefix.size();
    const auto [end, parsed] = std::from_chars(digits, name.data() + name.size(), pid);
    if (parsed != std::errc() || end != name.data() + name.size() || pid <= 0) continue;
    if (!entry.is_regular_file(error) || entry.is_symlink(error)) continue;
    if (::kill(pid, 0) != 0 && errno == ESRCH) std::filesystem::remove(entry.path(), error);
  }
}

}  // namespace

OutputFile::OutputFile(std::filesystem::path target)
    : target_(std::move(target)),
      partial_(target_.string() + std::string(kPartial) + std::to_string(::getpid())) {
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
  if (core::is_project_file(target_)) {
    throw core::InputError(target_.string(), {},
                           "is a scanbench project; scanbench never writes over a project");
  }
  remove_abandoned_partials(target_);
  ::unlink(partial_.c_str());  // an earlier process of our pid, long gone
  const int fd =
      ::open(partial_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0) {
    const int code = errno;
    const std::string problem = std::string("cannot create the output: ") + std::strerror(code);
    if (code == ENOENT || code == ENOTDIR) {  // the path is the user's
      const std::filesystem::path folder = target_.parent_path();
      throw core::InputError(target_.string(), {},
                             "cannot create the output: its folder " +
                                 (folder.empty() ? std::string(".") : folder.string()) +
                                 " is not an existing folder");
    }
    if (code == ENAMETOOLONG) throw core::InputError(target_.string(), {}, problem);
    throw core::RuntimeFailure(target_.string(), {}, problem);
  }
  file_ = ::fdopen(fd, "wb");
  if (file_ == nullptr) {
    ::close(fd);
    ::unlink(partial_.c_str());
    fail("cannot create");
  }
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

void OutputFile::rewrite(std::uint64_t offset, std::string_view bytes) {
  assert(file_ != nullptr && "rewrite after close");
  flush();
  [[maybe_unused]] const long end = std::ftell(file_);
  assert(end >= 0 && offset + bytes.size() <= static_cast<std::uint64_t>(end) &&
         "rewrite past what was written");
  if (std::fseek(file_, static_cast<long>(offset), SEEK_SET) != 0 ||
      std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size() ||
      std::fseek(file_, 0, SEEK_END) != 0) {
    fail("cannot write");
  }
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
  // On the disk before it replaces the target: a power cut after the rename
  // must not leave an empty file where the old one was.
  const bool synced = std::fflush(file_) == 0 && ::fsync(::fileno(file_)) == 0;
  const int saved = errno;
  const int closed = std::fclose(file_);
  file_ = nullptr;
  closed_ = true;
  if (!synced) errno = saved;
  if (!synced || closed != 0) fail("cannot write");
}

void OutputFile::commit() {
  close();
  std::error_code error;
  std::filesystem::rename(partial_, target_, error);
  if (error) {
    throw core::RuntimeFailure(target_.string(), {}, "cannot replace: " + error.message());
  }
  closed_ = false;  // renamed: nothing left to remove
}

void OutputFile::fail(const std::string& what) const {
  throw core::RuntimeFailure(target_.string(), {}, what + ": " + std::strerror(errno));
}

void write_files_together(const std::vector<std::pair<std::filesystem::path, std::string>>& files) {
  std::vector<std::unique_ptr<OutputFile>> outputs;
  for (const auto& [path, bytes] : files) {
    outputs.push_back(std::make_unique<OutputFile>(path));
    outputs.back()->write(bytes);
  }
  for (auto& output : outputs) output->close();
  for (auto& output : outputs) output->commit();
}

}  // namespace scanbench::acquisition
