// CRC-32C (Castagnoli: reflected polynomial 0x82F63B78, initial value and
// final xor 0xFFFFFFFF), the checksum of every E57 page (ASTM E2807 §7).
// Uses the SSE4.2 crc32 instruction when the processor has it (about
// 10 GB/s), else an 8-table software loop; both give the same value.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace scanbench::acquisition {

// The CRC-32C of `bytes` ("123456789" gives 0xE3069283).
std::uint32_t crc32c(std::span<const std::byte> bytes);

// The same by the table-driven loop alone, whatever the processor has (for
// tests that compare the two paths).
std::uint32_t crc32c_portable(std::span<const std::byte> bytes);

}  // namespace scanbench::acquisition
