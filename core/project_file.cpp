#include "core/project_file.hpp"

#include <algorithm>
#include <array>
#include <fstream>

namespace scanbench::core {

bool is_project_file(const std::filesystem::path& file) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) return false;
  std::array<unsigned char, 100> header{};
  std::ifstream in(file, std::ios::binary);
  in.read(reinterpret_cast<char*>(header.data()), header.size());
  if (in.gcount() != static_cast<std::streamsize>(header.size())) return false;
  constexpr char kMagic[16] = "SQLite format 3";  // with its terminating NUL: 16 bytes
  const std::uint32_t application_id = (std::uint32_t{header[68]} << 24) |
                                       (std::uint32_t{header[69]} << 16) |
                                       (std::uint32_t{header[70]} << 8) | std::uint32_t{header[71]};
  return std::equal(kMagic, kMagic + 16, header.begin()) && application_id == kProjectApplicationId;
}

}  // namespace scanbench::core
