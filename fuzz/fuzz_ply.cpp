// libFuzzer target: the PLY reader (ASCII and binary bodies).
#include "acquisition/formats/ply_reader.hpp"
#include "fuzz/fuzz_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = scanbench::fuzz::write_input(data, size, "input.ply");
  scanbench::fuzz::expect_refusal_or_success([&] { scanbench::acquisition::read_ply(path); });
  return 0;
}
