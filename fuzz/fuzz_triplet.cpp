// libFuzzer target: the image-triplet sidecar (and, through it, the image
// loading): the input is the JSON sidecar; small valid images of the good
// triplet fixture lie beside it under their own names, so that sidecars
// naming them go on into image decoding.
#include <cstring>

#include "acquisition/formats/triplet_reader.hpp"
#include "fuzz/fuzz_file.hpp"

namespace {

void copy_fixture_images() {
  static const bool copied = [] {
    for (const char* name : {"small_range.png", "small_intensity.png", "small_color.png"}) {
      const std::filesystem::path from =
          std::filesystem::path(SCANBENCH_FIXTURES_DIR) / "good/triplet" / name;
      std::filesystem::copy_file(from, scanbench::fuzz::work_folder() / name,
                                 std::filesystem::copy_options::overwrite_existing);
    }
    return true;
  }();
  static_cast<void>(copied);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  copy_fixture_images();
  const std::filesystem::path path = scanbench::fuzz::write_input(data, size, "input.json");
  scanbench::fuzz::expect_refusal_or_success([&] { scanbench::acquisition::read_triplet(path); });
  return 0;
}
