#include "acquisition/scan_source.hpp"

namespace scanbench::acquisition {

const char* projection_name(ImageProjection projection) {
  switch (projection) {
    case ImageProjection::kPinhole:
      return "pinhole";
    case ImageProjection::kSpherical:
      return "spherical";
    case ImageProjection::kCylindrical:
      return "cylindrical";
    case ImageProjection::kVisualReference:
      return "visual_reference";
  }
  return "visual_reference";
}

}  // namespace scanbench::acquisition
