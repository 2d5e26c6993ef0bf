// The binary section of an E57 compressed vector (ASTM E2807 §9): a 32-byte
// section header, then data packets of at most 64 KiB, each carrying a
// slice of every field's bytestream. Index packets are optional and
// neither written nor needed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "acquisition/formats/e57/e57_bitpack.hpp"
#include "acquisition/formats/e57/e57_document.hpp"
#include "acquisition/formats/e57/e57_pages.hpp"

namespace scanbench::acquisition {

// Every field's whole bytestream (one per field of `points`, in prototype
// order), gathered from the section's data packets. Throws core::InputError
// naming the file, `what` and the packet's byte offset for a bad section
// header or packet, a packet whose stream count differs from the
// prototype's, or streams too short for the record count (a truncated
// section, or a prototype that does not match its data).
std::vector<std::vector<std::byte>> read_e57_streams(E57PageReader& file,
                                                     const E57PointsEntry& points,
                                                     const std::string& what);

// Fills columns[f][i] with field f's value of record first + i, for
// `count` records.
using E57RecordSource = std::function<void(std::uint64_t first, std::uint64_t count,
                                           std::vector<std::vector<double>>& columns)>;

// Writes a compressed vector section of `records` records of `fields`,
// asking `source` for the values packet by packet, and returns the
// section's physical offset (the XML's fileOffset).
std::uint64_t write_e57_points(E57PageWriter& file, std::span<const E57Field> fields,
                               std::uint64_t records, const E57RecordSource& source);

}  // namespace scanbench::acquisition
