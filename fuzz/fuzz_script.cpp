// libFuzzer target: the segment script file (`segment --script`), read and
// checked whole as before anything of it runs.
#include "app/formats/segment_script_file.hpp"
#include "fuzz/fuzz_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = scanbench::fuzz::write_input(data, size, "ops.json");
  scanbench::fuzz::expect_refusal_or_success(
      [&] { scanbench::app::read_segment_script(path); });
  return 0;
}
