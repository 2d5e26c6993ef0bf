#include "acquisition/scan_source.hpp"

#include <sys/stat.h>

namespace scanbench::acquisition {

SourceFile identify_source_file(const std::filesystem::path& path) {
  std::error_code error;
  SourceFile file;
  file.path =
      std::filesystem::weakly_canonical(std::filesystem::absolute(path, error), error).string();
  struct stat status {};
  if (::stat(path.c_str(), &status) == 0) {
    file.device = static_cast<std::uint64_t>(status.st_dev);
    file.inode = static_cast<std::uint64_t>(status.st_ino);
  }
  return file;
}

void identify_source_files(const std::filesystem::path& path, ScanSource& source) {
  source.files = {identify_source_file(path)};
  for (const std::filesystem::path& companion : source.companion_files)
    source.files.push_back(identify_source_file(companion));
}

bool names_source_file(const std::filesystem::path& output, const SourceFile& source) {
  if (source.path.empty()) return false;
  const SourceFile out = identify_source_file(output);
  if (out.path == source.path) return true;
  return out.inode != 0 && out.device == source.device && out.inode == source.inode;
}

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
