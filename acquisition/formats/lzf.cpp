#include "acquisition/formats/lzf.hpp"

#include <cstring>

namespace scanbench::acquisition {

std::optional<std::string> lzf_decompress(std::span<const std::uint8_t> in,
                                          std::span<std::uint8_t> out) {
  std::size_t ip = 0;
  std::size_t op = 0;
  while (ip < in.size()) {
    const unsigned control = in[ip++];
    if (control < 32) {  // a literal run of control + 1 bytes
      const std::size_t length = control + 1;
      if (ip + length > in.size()) return "a literal run reads past the end of the data";
      if (op + length > out.size()) return "a literal run writes past the declared size";
      std::memcpy(out.data() + op, in.data() + ip, length);
      ip += length;
      op += length;
      continue;
    }
    std::size_t length = control >> 5;
    if (length == 7) {
      if (ip >= in.size()) return "a back reference is cut off";
      length += in[ip++];
    }
    if (ip >= in.size()) return "a back reference is cut off";
    const std::size_t distance = ((control & 31u) << 8) + in[ip++] + 1;
    length += 2;
    if (distance > op) return "a back reference points before the start";
    if (op + length > out.size()) return "a back reference writes past the declared size";
    // Byte by byte: the source may overlap what this run writes.
    for (std::size_t k = 0; k < length; ++k, ++op) out[op] = out[op - distance];
  }
  if (op != out.size()) {
    return "decodes to " + std::to_string(op) + " bytes, the header declares " +
           std::to_string(out.size());
  }
  return std::nullopt;
}

}  // namespace scanbench::acquisition
