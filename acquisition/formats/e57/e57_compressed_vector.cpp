#include "acquisition/formats/e57/e57_compressed_vector.hpp"

#include <algorithm>
#include <cassert>
#include <cstring>

#include "core/errors.hpp"

namespace scanbench::acquisition {
namespace {

constexpr std::uint64_t kSectionHeaderBytes = 32;
constexpr std::uint64_t kMaxPacketBytes = 65536;
constexpr std::uint8_t kDataPacket = 1;
constexpr std::uint8_t kEmptyPacket = 2;

std::uint64_t load_u64(const std::byte* at) {
  std::uint64_t value;
  std::memcpy(&value, at, 8);  // little-endian host
  return value;
}
std::uint16_t load_u16(const std::byte* at) {
  std::uint16_t value;
  std::memcpy(&value, at, 2);
  return value;
}
template <typename T>
void store(std::vector<std::byte>& out, std::size_t at, T value) {
  assert(at + sizeof(T) <= out.size());
  std::memcpy(out.data() + at, &value, sizeof(T));  // little-endian host
}

// The logical offset of physical offset `physical` (not inside a checksum).
std::uint64_t logical_of(std::uint64_t physical) {
  return physical / kE57PageSize * kE57PagePayload + physical % kE57PageSize;
}

[[noreturn]] void bad(const E57PageReader& file, std::uint64_t physical, const std::string& what,
                      const std::string& problem) {
  core::FilePosition position;
  position.byte_offset = physical;
  position.detail = what;
  throw core::InputError(file.file_name(), position, problem);
}

// Packet header of a data packet: the stream lengths, after type, flags,
// length and count.
struct PacketLayout {
  std::uint64_t bytes = 0;  // whole packet, padded to a multiple of 4
  std::vector<std::uint64_t> stream_bytes;
};

PacketLayout layout_packet(std::span<const E57Field> fields, std::uint64_t count) {
  PacketLayout layout;
  std::uint64_t bytes = 6 + 2 * fields.size();
  for (const E57Field& field : fields) {
    layout.stream_bytes.push_back(e57_stream_bytes(field, count));
    bytes += layout.stream_bytes.back();
  }
  layout.bytes = (bytes + 3) / 4 * 4;
  return layout;
}

// Records per packet: a multiple of 8 (so that every stream's slice ends on
// a whole byte) that keeps the packet within 64 KiB.
std::uint64_t records_per_packet(std::span<const E57Field> fields) {
  std::uint64_t bits = 0;  // per record, all fields
  for (const E57Field& field : fields) bits += static_cast<std::uint64_t>(field.bits());
  const std::uint64_t budget = kMaxPacketBytes - 12 - 2 * fields.size();  // header and padding
  if (bits == 0) return 1u << 20;
  return std::max<std::uint64_t>(8, budget / bits * 8);  // bits per record = bytes per 8 records
}

// The section's extent in logical bytes and where its first packet starts,
// checked against the file.
struct Section {
  std::uint64_t bytes = 0;        // sectionLogicalLength
  std::uint64_t end = 0;          // logical offset just past the section
  std::uint64_t data_offset = 0;  // physical offset of the first packet
};

Section read_section_header(E57PageReader& file, const E57PointsEntry& points,
                            const std::string& what) {
  std::byte header[kSectionHeaderBytes];
  file.read(points.file_offset, header, what + " section header");
  Section section;
  section.bytes = load_u64(header + 8);
  section.data_offset = load_u64(header + 16);
  const std::uint64_t start = logical_of(points.file_offset);
  const std::uint64_t file_bytes = logical_of(file.physical_length());
  if (std::to_integer<int>(header[0]) != 1 || section.bytes < kSectionHeaderBytes ||
      section.bytes % 4 != 0) {
    bad(file, points.file_offset, what, "is not a compressed-vector section header");
  }
  if (section.bytes > file_bytes - start) {
    bad(file, points.file_offset, what,
        "has a section length of " + std::to_string(section.bytes) +
            " bytes, beyond the end of the file (truncated?)");
  }
  section.end = start + section.bytes;
  if (section.data_offset % kE57PageSize >= kE57PagePayload ||
      section.data_offset >= file.physical_length() ||
      logical_of(section.data_offset) > section.end ||
      logical_of(section.data_offset) < start + kSectionHeaderBytes) {
    bad(file, points.file_offset, what, "has a data offset outside its section");
  }
  // Every record takes at least a bit, but for fields that never vary; a
  // million such records at most.
  if (points.record_count / 8 > section.bytes + (1u << 17)) {
    bad(file, points.file_offset, what,
        "has a recordCount of " + std::to_string(points.record_count) +
            ", more than its section of " + std::to_string(section.bytes) + " bytes can hold");
  }
  return section;
}

// Appends the bytestream slices of the data packet `packet` (read from
// physical offset `at`) to `streams`.
void append_packet_streams(const E57PageReader& file, std::uint64_t at,
                           std::span<const std::byte> packet, const std::string& what,
                           std::vector<std::vector<std::byte>>& streams) {
  if (packet.size() < 6) bad(file, at, what, "has a data packet too short for its header");
  const std::uint64_t count = load_u16(packet.data() + 4);
  if (count != streams.size()) {
    bad(file, at, what,
        "has a packet of " + std::to_string(count) + " bytestreams where the prototype has " +
            std::to_string(streams.size()) + " fields");
  }
  std::uint64_t offset = 6 + 2 * count;
  if (offset > packet.size()) bad(file, at, what, "has a packet too short for its stream table");
  for (std::size_t f = 0; f < count; ++f) {
    const std::uint64_t bytes = load_u16(packet.data() + 6 + 2 * f);
    if (offset + bytes > packet.size())
      bad(file, at, what, "has a packet whose streams overrun it");
    const auto slice = packet.subspan(offset, bytes);
    streams[f].insert(streams[f].end(), slice.begin(), slice.end());
    offset += bytes;
  }
}

}  // namespace

std::vector<std::vector<std::byte>> read_e57_streams(E57PageReader& file,
                                                     const E57PointsEntry& points,
                                                     const std::string& what) {
  const Section section = read_section_header(file, points, what);
  std::vector<std::vector<std::byte>> streams(points.fields.size());
  for (std::size_t f = 0; f < streams.size(); ++f) {
    streams[f].reserve(
        std::min(e57_stream_bytes(points.fields[f], points.record_count), section.bytes));
  }
  std::vector<std::byte> packet;
  for (std::uint64_t at = section.data_offset; logical_of(at) < section.end;) {
    std::byte common[4];
    file.read(at, common, what + " packet");
    const int type = std::to_integer<int>(common[0]);
    const std::uint64_t length = std::uint64_t{load_u16(common + 2)} + 1;
    if (type > kEmptyPacket || length % 4 != 0 || logical_of(at) + length > section.end) {
      bad(file, at, what, "holds a packet of unknown type or impossible length");
    }
    if (type == kDataPacket) {
      packet.resize(length);
      file.read(at, packet, what + " packet");
      append_packet_streams(file, at, packet, what, streams);
    }
    // Index packets (type 0) and empty packets carry no records.
    at = e57_advance(at, length);
  }
  for (std::size_t f = 0; f < streams.size(); ++f) {
    if (streams[f].size() < e57_stream_bytes(points.fields[f], points.record_count)) {
      bad(file, points.file_offset, what,
          "holds fewer bytes of field \"" + points.fields[f].name + "\" than its " +
              std::to_string(points.record_count) +
              " records need (a truncated section, or a prototype that does not match its data)");
    }
  }
  return streams;
}

std::uint64_t write_e57_points(E57PageWriter& file, std::span<const E57Field> fields,
                               std::uint64_t records, const E57RecordSource& source) {
  assert(!fields.empty() && fields.size() < 2048);
  const std::uint64_t per_packet = records_per_packet(fields);
  // Records of each packet; a vector of no records still has one packet.
  std::vector<std::uint64_t> counts;
  for (std::uint64_t first = 0; first < records; first += per_packet) {
    counts.push_back(std::min(per_packet, records - first));
  }
  if (counts.empty()) counts.push_back(0);
  std::uint64_t packets_bytes = 0;
  for (const std::uint64_t count : counts) packets_bytes += layout_packet(fields, count).bytes;
  file.pad_to(4);
  const std::uint64_t section = file.physical_position();
  std::vector<std::byte> bytes(kSectionHeaderBytes, std::byte{0});
  bytes[0] = std::byte{1};  // compressed-vector section
  store<std::uint64_t>(bytes, 8, kSectionHeaderBytes + packets_bytes);
  store<std::uint64_t>(bytes, 16, e57_advance(section, kSectionHeaderBytes));
  store<std::uint64_t>(bytes, 24, 0);  // no index packet
  file.write(bytes);
  std::vector<std::vector<double>> columns(fields.size());
  std::uint64_t first = 0;
  for (const std::uint64_t count : counts) {
    const PacketLayout layout = layout_packet(fields, count);
    assert(layout.bytes <= kMaxPacketBytes);
    for (auto& column : columns) column.assign(count, 0.0);
    if (count > 0) source(first, count, columns);
    bytes.assign(6 + 2 * fields.size(), std::byte{0});
    bytes[0] = std::byte{kDataPacket};  // flags (byte 1) 0
    store<std::uint16_t>(bytes, 2, static_cast<std::uint16_t>(layout.bytes - 1));
    store<std::uint16_t>(bytes, 4, static_cast<std::uint16_t>(fields.size()));
    for (std::size_t f = 0; f < fields.size(); ++f) {
      store<std::uint16_t>(bytes, 6 + 2 * f, static_cast<std::uint16_t>(layout.stream_bytes[f]));
    }
    for (std::size_t f = 0; f < fields.size(); ++f) e57_pack(fields[f], columns[f], bytes);
    bytes.resize(layout.bytes, std::byte{0});
    file.write(bytes);
    first += count;
  }
  return section;
}

}  // namespace scanbench::acquisition
