#include "acquisition/formats/e57/e57_pages.hpp"

#include <algorithm>
#include <cassert>
#include <cerrno>
#include <cstring>

#include "acquisition/formats/e57/crc32c.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition {
namespace {

constexpr std::uint64_t kChunkPages = 256;  // read 256 KiB at a time

// The checksum is stored as a big-endian 32-bit number after the payload.
std::uint32_t stored_checksum(const std::byte* page) {
  std::uint32_t value = 0;
  for (std::uint64_t i = 0; i < 4; ++i) {
    value = (value << 8) | std::to_integer<std::uint32_t>(page[kE57PagePayload + i]);
  }
  return value;
}

void store_checksum(std::uint32_t crc, std::vector<std::byte>& page) {
  for (int i = 3; i >= 0; --i) {
    page.push_back(static_cast<std::byte>((crc >> (8 * i)) & 0xFFu));
  }
}

}  // namespace

std::uint64_t e57_advance(std::uint64_t physical_start, std::uint64_t logical) {
  const std::uint64_t page = physical_start / kE57PageSize;
  const std::uint64_t in_page = physical_start % kE57PageSize;
  assert(in_page < kE57PagePayload && "physical offset inside a checksum");
  const std::uint64_t total = in_page + logical;
  return (page + total / kE57PagePayload) * kE57PageSize + total % kE57PagePayload;
}

E57PageReader::E57PageReader(const std::filesystem::path& path) : name_(path.string()) {
  file_ = std::fopen(name_.c_str(), "rb");
  if (file_ == nullptr) {
    throw core::InputError(name_, {}, std::string("cannot open: ") + std::strerror(errno));
  }
  std::error_code error;
  length_ = std::filesystem::file_size(path, error);
  if (error || length_ == 0 || length_ % kE57PageSize != 0) {
    std::fclose(file_);
    throw core::InputError(name_, {},
                           "not an E57 file: its length (" + std::to_string(length_) +
                               " bytes) is not a whole number of 1024-byte pages");
  }
  checked_.assign(length_ / kE57PageSize, 0);
}

E57PageReader::~E57PageReader() {
  if (file_ != nullptr) std::fclose(file_);
}

void E57PageReader::load_chunk(std::uint64_t first_page, const std::string& what) {
  const std::uint64_t pages = std::min(kChunkPages, checked_.size() - first_page);
  chunk_.resize(pages * kE57PageSize);
  if (std::fseek(file_, static_cast<long>(first_page * kE57PageSize), SEEK_SET) != 0 ||
      std::fread(chunk_.data(), 1, chunk_.size(), file_) != chunk_.size()) {
    throw core::RuntimeFailure(name_, {}, "cannot read the " + what);
  }
  chunk_first_page_ = first_page;
}

void E57PageReader::check_page(std::uint64_t page, const std::string& what) {
  if (checked_[page]) return;
  const std::byte* bytes = chunk_.data() + (page - chunk_first_page_) * kE57PageSize;
  const std::uint32_t computed = crc32c({bytes, kE57PagePayload});
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
  const bool fuzzing = true;  // see CMakeLists.txt, SCANBENCH_FUZZ
#else
  const bool fuzzing = false;
#endif
  if (computed != stored_checksum(bytes) && !fuzzing) {
    core::FilePosition position;
    position.byte_offset = page * kE57PageSize;
    position.detail = "page " + std::to_string(page);
    throw core::InputError(name_, position,
                           "page fails its CRC-32C checksum (the file is damaged), in the " + what);
  }
  checked_[page] = 1;
}

void E57PageReader::read(std::uint64_t physical, std::span<std::byte> out,
                         const std::string& what) {
  std::size_t done = 0;
  while (done < out.size()) {
    const std::uint64_t page = physical / kE57PageSize;
    const std::uint64_t in_page = physical % kE57PageSize;
    if (page >= checked_.size() || in_page >= kE57PagePayload) {
      core::FilePosition position;
      position.byte_offset = physical;
      throw core::InputError(name_, position,
                             page >= checked_.size()
                                 ? "the " + what + " runs past the end of the file (truncated?)"
                                 : "the " + what + " starts inside a page checksum");
    }
    if (chunk_.empty() || page < chunk_first_page_ ||
        page >= chunk_first_page_ + chunk_.size() / kE57PageSize) {
      load_chunk(page, what);
    }
    check_page(page, what);
    const std::size_t take = std::min<std::size_t>(out.size() - done, kE57PagePayload - in_page);
    std::memcpy(out.data() + done,
                chunk_.data() + (page - chunk_first_page_) * kE57PageSize + in_page, take);
    done += take;
    physical = (page + 1) * kE57PageSize;
  }
}

std::uint64_t E57PageWriter::physical_position() const {
  return (logical_ / kE57PagePayload) * kE57PageSize + logical_ % kE57PagePayload;
}

void E57PageWriter::write(std::span<const std::byte> bytes) {
  while (!bytes.empty()) {
    const std::size_t take = std::min<std::size_t>(bytes.size(), kE57PagePayload - page_.size());
    page_.insert(page_.end(), bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(take));
    bytes = bytes.subspan(take);
    logical_ += take;
    if (page_.size() == kE57PagePayload) flush_page();
  }
}

void E57PageWriter::pad_to(std::uint64_t alignment) {
  static const std::vector<std::byte> zeros(64);
  assert(alignment > 0 && alignment <= zeros.size());
  const std::uint64_t pad = (alignment - logical_ % alignment) % alignment;
  write({zeros.data(), pad});
}

void E57PageWriter::flush_page() {
  if (first_page_.empty() && logical_ <= kE57PagePayload) first_page_ = page_;
  store_checksum(crc32c(page_), page_);
  out_.write({reinterpret_cast<const char*>(page_.data()), page_.size()});
  page_.clear();
}

std::uint64_t E57PageWriter::finish(std::uint64_t logical, std::span<const std::byte> bytes) {
  assert(logical + bytes.size() <= kE57PagePayload && "the header lies in the first page");
  if (!page_.empty()) {
    page_.resize(kE57PagePayload);  // zeros to the end of the page
    logical_ = (logical_ / kE57PagePayload + 1) * kE57PagePayload;
    flush_page();
  }
  std::vector<std::byte> first = first_page_;
  std::copy(bytes.begin(), bytes.end(), first.begin() + static_cast<std::ptrdiff_t>(logical));
  store_checksum(crc32c(first), first);
  out_.rewrite(0, {reinterpret_cast<const char*>(first.data()), first.size()});
  return (logical_ / kE57PagePayload) * kE57PageSize;
}

}  // namespace scanbench::acquisition
