#include "acquisition/formats/e57/e57_reader.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <optional>

#include "acquisition/formats/e57/e57_compressed_vector.hpp"
#include "acquisition/formats/e57/e57_document.hpp"
#include "acquisition/formats/e57/e57_pages.hpp"
#include "acquisition/formats/e57/e57_scan_grid.hpp"
#include "core/errors.hpp"

namespace scanbench::acquisition {
namespace {

constexpr std::uint64_t kHeaderBytes = 48;

struct FileHeader {
  std::uint64_t physical_length = 0;
  std::uint64_t xml_offset = 0;
  std::uint64_t xml_length = 0;
};

[[noreturn]] void bad_header(const E57PageReader& file, std::uint64_t offset,
                             const std::string& problem) {
  core::FilePosition position;
  position.byte_offset = offset;
  position.detail = "file header";
  throw core::InputError(file.file_name(), position, problem);
}

FileHeader read_header(E57PageReader& file) {
  std::byte bytes[kHeaderBytes];
  file.read(0, bytes, "file header");
  if (std::memcmp(bytes, "ASTM-E57", 8) != 0) {
    bad_header(file, 0, "not an E57 file: the signature is not \"ASTM-E57\"");
  }
  std::uint32_t major = 0;
  std::memcpy(&major, bytes + 8, 4);
  FileHeader header;
  std::uint64_t page_size = 0;
  std::memcpy(&header.physical_length, bytes + 16, 8);
  std::memcpy(&header.xml_offset, bytes + 24, 8);
  std::memcpy(&header.xml_length, bytes + 32, 8);
  std::memcpy(&page_size, bytes + 40, 8);
  if (major != 1)
    bad_header(file, 8, "E57 major version " + std::to_string(major) + " (1 is read)");
  if (page_size != kE57PageSize) bad_header(file, 40, "page size is not 1024");
  if (header.physical_length != file.physical_length()) {
    bad_header(file, 16,
               "the header gives a length of " + std::to_string(header.physical_length) +
                   " bytes but the file has " + std::to_string(file.physical_length()) +
                   " (truncated or appended to)");
  }
  if (header.xml_length == 0 || header.xml_length > file.physical_length()) {
    bad_header(file, 32, "impossible XML section length");
  }
  return header;
}

ScanImage read_image(E57PageReader& file, const E57ImageEntry& entry) {
  ScanImage image = entry.image;
  const std::string what = "image blob of " + entry.path;
  std::byte header[16];
  file.read(entry.blob_offset, header, what);
  std::uint64_t section_bytes = 0;
  std::memcpy(&section_bytes, header + 8, 8);
  if (std::to_integer<int>(header[0]) != 0 || entry.blob_length > file.physical_length() ||
      section_bytes < 16 + entry.blob_length) {
    core::FilePosition position;
    position.byte_offset = entry.blob_offset;
    position.detail = entry.path;
    throw core::InputError(
        file.file_name(), position,
        "is not a blob section of " + std::to_string(entry.blob_length) + " bytes");
  }
  image.data.resize(entry.blob_length);
  file.read(e57_advance(entry.blob_offset, 16), std::as_writable_bytes(std::span(image.data)),
            what);
  return image;
}

// Refuses image entries whose blob sections are one and the same, or
// overlap: each image needs bytes of its own, so the count and the memory
// images take are bounded by the file's size, however often the XML
// repeats an entry.
void check_image_blobs(const E57Document& document, const E57PageReader& file) {
  const auto refuse = [&file](const E57ImageEntry& entry, const std::string& problem) {
    core::FilePosition position;
    position.byte_offset = entry.blob_offset;
    position.detail = "XML element " + entry.path;
    throw core::InputError(file.file_name(), position, problem);
  };
  std::vector<const E57ImageEntry*> images;
  for (const E57ImageEntry& entry : document.images) {
    if (entry.blob_offset >= file.physical_length() ||
        entry.blob_offset % kE57PageSize >= kE57PagePayload)
      refuse(entry, "its blob starts beyond the end of the file or inside a page checksum");
    if (entry.blob_length > file.physical_length())
      refuse(entry,
             "its blob of " + std::to_string(entry.blob_length) + " bytes is longer than the file");
    images.push_back(&entry);
  }
  std::sort(images.begin(), images.end(), [](const E57ImageEntry* a, const E57ImageEntry* b) {
    return a->blob_offset < b->blob_offset;
  });
  for (std::size_t k = 1; k < images.size(); ++k) {
    const E57ImageEntry& before = *images[k - 1];
    if (images[k]->blob_offset < e57_advance(before.blob_offset, 16 + before.blob_length)) {
      refuse(*images[k], "its blob is, or overlaps, the blob of " + before.path +
                             ": each image needs a blob of its own");
    }
  }
}

}  // namespace

void read_e57(const std::filesystem::path& path, const std::function<void(ImportedScan&&)>& on_scan,
              const std::function<void(ScanImage&&)>& on_loose_image) {
  E57PageReader file(path);
  const FileHeader header = read_header(file);
  std::string xml(header.xml_length, '\0');
  file.read(header.xml_offset, std::as_writable_bytes(std::span(xml)), "XML section");
  const E57Document document = parse_e57_xml(xml, file.file_name());
  if (document.scans.empty()) {
    core::FilePosition position;
    position.detail = "XML element /data3D";
    throw core::InputError(file.file_name(), position, "holds no scan");
  }
  for (const E57ScanEntry& entry : document.scans) {
    if (entry.points.record_count > 0) continue;
    core::FilePosition position;
    position.detail = "XML element " + entry.path + "/points";
    throw core::InputError(file.file_name(), position, "holds no point records");
  }
  check_image_blobs(document, file);
  std::vector<bool> image_taken(document.images.size(), false);
  for (std::size_t k = 0; k < document.scans.size(); ++k) {
    const E57ScanEntry& entry = document.scans[k];
    std::vector<ImportedScan> scans = scans_from_records(
        path, entry, k, read_e57_streams(file, entry.points, "points of " + entry.path));
    ImportedScan& scan = scans.front();
    for (std::size_t i = 0; i < document.images.size(); ++i) {
      // An image goes with the first scan of its guid.
      if (image_taken[i] || entry.guid.empty() ||
          document.images[i].associated_scan_guid != entry.guid) {
        continue;
      }
      scan.images.push_back(read_image(file, document.images[i]));
      image_taken[i] = true;
    }
    for (ImportedScan& each : scans) {
      each.source.coordinate_metadata = document.coordinate_metadata;
      on_scan(std::move(each));
    }
  }
  for (std::size_t i = 0; i < document.images.size(); ++i) {
    if (!image_taken[i] && on_loose_image) on_loose_image(read_image(file, document.images[i]));
  }
}

}  // namespace scanbench::acquisition
