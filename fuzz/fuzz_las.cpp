// libFuzzer target: the LAS reader (header, variable length records, points).
#include "acquisition/formats/las_reader.hpp"
#include "fuzz/fuzz_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = scanbench::fuzz::write_input(data, size, "input.las");
  scanbench::fuzz::expect_refusal_or_success([&] { scanbench::acquisition::read_las(path); });
  return 0;
}
