// The physical layer of an E57 file (ASTM E2807 §7): the file is a sequence
// of 1024-byte pages, each 1020 bytes of payload followed by the CRC-32C of
// that payload. Everything above this layer (the header, the XML, blobs and
// compressed vectors) is a "logical" byte stream laid across the payloads;
// offsets stored in the file are physical, lengths logical.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "acquisition/formats/output_file.hpp"

namespace scanbench::acquisition {

inline constexpr std::uint64_t kE57PageSize = 1024;
inline constexpr std::uint64_t kE57PagePayload = 1020;

// The physical offset of the byte `logical` bytes after physical offset
// `physical_start` (which must lie in a payload), skipping the checksums.
std::uint64_t e57_advance(std::uint64_t physical_start, std::uint64_t logical);

// Reads the logical bytes of an E57 file, checking each page's checksum the
// first time any of its bytes is read.
class E57PageReader {
 public:
  // Opens `path`. Throws core::InputError naming the file when it cannot be
  // opened or its length is not a whole number of pages.
  explicit E57PageReader(const std::filesystem::path& path);
  ~E57PageReader();
  E57PageReader(const E57PageReader&) = delete;
  E57PageReader& operator=(const E57PageReader&) = delete;

  std::uint64_t physical_length() const { return length_; }
  const std::string& file_name() const { return name_; }

  // Fills `out` with the logical bytes starting at physical offset
  // `physical`. Throws core::InputError naming the file, the page and its
  // byte offset when a page fails its checksum, and naming `what` (the part
  // being read: "XML section", "blob of image 2 …") when the bytes run past
  // the end of the file or `physical` points into a checksum.
  void read(std::uint64_t physical, std::span<std::byte> out, const std::string& what);

 private:
  void load_chunk(std::uint64_t first_page, const std::string& what);
  // Verifies page `page` (in the chunk) the first time it is read; `what`
  // names the part being read for the error.
  void check_page(std::uint64_t page, const std::string& what);

  std::string name_;
  std::FILE* file_ = nullptr;
  std::uint64_t length_ = 0;
  std::uint64_t chunk_first_page_ = 0;  // pages held in chunk_
  std::vector<std::byte> chunk_;
  std::vector<std::uint8_t> checked_;  // one per page: its checksum was verified
};

// Writes the logical byte stream of an E57 file into pages with their
// checksums, through an OutputFile (a .partial file renamed on commit).
class E57PageWriter {
 public:
  explicit E57PageWriter(OutputFile& out) : out_(out) {}

  // Where the next logical byte will land.
  std::uint64_t physical_position() const;
  std::uint64_t logical_position() const { return logical_; }

  void write(std::span<const std::byte> bytes);
  // Zero bytes up to the next multiple of `alignment` logical bytes.
  void pad_to(std::uint64_t alignment);

  // Overwrites `bytes` at logical offset `logical` of the first page (the
  // file header, known only at the end), pads the last page with zeros and
  // writes every checksum. Returns the physical length of the file.
  std::uint64_t finish(std::uint64_t logical, std::span<const std::byte> bytes);

 private:
  void flush_page();

  OutputFile& out_;
  std::uint64_t logical_ = 0;
  std::vector<std::byte> page_;        // payload of the page being filled
  std::vector<std::byte> first_page_;  // payload of page 0, rewritten by finish()
};

}  // namespace scanbench::acquisition
