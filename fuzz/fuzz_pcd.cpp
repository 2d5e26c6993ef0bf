// libFuzzer target: the organized-PCD reader (ASCII, binary, compressed).
#include "acquisition/formats/pcd_reader.hpp"
#include "fuzz/fuzz_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = scanbench::fuzz::write_input(data, size, "input.pcd");
  scanbench::fuzz::expect_refusal_or_success(
      [&] { scanbench::acquisition::read_pcd(path); });
  return 0;
}
