// libFuzzer target: the E57 reader (page checksums not enforced in the fuzz
// build, so that mutations reach the XML and the compressed vectors).
#include "acquisition/formats/e57/e57_reader.hpp"
#include "fuzz/fuzz_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = scanbench::fuzz::write_input(data, size, "input.e57");
  scanbench::fuzz::expect_refusal_or_success([&] {
    scanbench::acquisition::read_e57(
        path, [](scanbench::acquisition::ImportedScan&&) {},
        [](scanbench::acquisition::ScanImage&&) {});
  });
  return 0;
}
