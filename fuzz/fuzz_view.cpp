// libFuzzer target: the camera view file (`render --view`, `simulate
// --render-view`).
#include "acquisition/camera_view.hpp"
#include "fuzz/fuzz_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = scanbench::fuzz::write_input(data, size, "view.json");
  scanbench::fuzz::expect_refusal_or_success(
      [&] { scanbench::acquisition::read_camera_view(path); });
  return 0;
}
