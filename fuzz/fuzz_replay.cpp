// libFuzzer target: the workbench's replay file (`workbench --replay`), read
// and expanded into events as before any window opens.
#include "app/workbench/replay.hpp"
#include "fuzz/fuzz_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = scanbench::fuzz::write_input(data, size, "replay.json");
  scanbench::fuzz::expect_refusal_or_success([&] { scanbench::app::workbench::read_replay(path); });
  return 0;
}
