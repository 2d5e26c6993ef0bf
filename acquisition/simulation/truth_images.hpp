// Per-pixel truth channels as image files (OpenCV stays in the .cpp).
#pragma once

#include <filesystem>

#include "acquisition/simulation/virtual_scanner.hpp"

namespace scanbench::acquisition::sim {

struct TruthFiles {
  std::filesystem::path object_id;  // 16-bit PNG
  std::filesystem::path normal;     // 3 × float TIFF (x, y, z in channel order)
  std::filesystem::path range;      // float TIFF [m]
  std::filesystem::path mixed;      // 8-bit PNG, 255 = mixed
};

// Writes the four images of a rows × columns truth. Throws std::runtime_error
// naming the file when one cannot be written. Asserts the channel sizes.
void write_truth_images(const ScanTruth& truth, int rows, int columns, const TruthFiles& files);

// Reads them back; every image must be rows × columns of the documented type.
// Throws InputError naming the file and the problem otherwise.
ScanTruth read_truth_images(const TruthFiles& files, int rows, int columns);

}  // namespace scanbench::acquisition::sim
