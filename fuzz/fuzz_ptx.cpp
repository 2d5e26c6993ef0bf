// libFuzzer target: the Leica PTX reader.
#include "acquisition/formats/ptx_reader.hpp"
#include "fuzz/fuzz_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = scanbench::fuzz::write_input(data, size, "input.ptx");
  scanbench::fuzz::expect_refusal_or_success(
      [&] { scanbench::acquisition::read_ptx(path, {}, [](scanbench::acquisition::Scan&&) {}); });
  return 0;
}
