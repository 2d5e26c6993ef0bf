// LZF decompression, for the binary_compressed body of PCD files. The format
// (Marc Lehmann's liblzf, as PCL writes it) is a sequence of runs, each
// starting with a control byte c: c < 32 copies the next c + 1 bytes
// literally; otherwise it repeats earlier output: length (c >> 5) + 2 (with
// one more length byte added when c >> 5 is 7), from
// ((c & 31) << 8) + next byte + 1 bytes back.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace scanbench::acquisition {

// Decodes `in` into `out`, which must come out exactly full. Returns an
// empty optional on success, else what is wrong with the data (a run past
// the end of either buffer, a reference before the start, too little output).
std::optional<std::string> lzf_decompress(std::span<const std::uint8_t> in,
                                          std::span<std::uint8_t> out);

}  // namespace scanbench::acquisition
