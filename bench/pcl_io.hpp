// PCL's own PCD reader, as the peer of our PTX reader in `bench io`. The
// header exposes no PCL type; PCL stays in pcl_io.cpp.
#pragma once

#include <cstddef>
#include <filesystem>

namespace scanbench::bench {

// Reads `pcd` with pcl::PCDReader into a PCLPointCloud2 and returns its point
// count. Throws std::runtime_error naming the file when PCL fails.
std::size_t read_pcd_with_pcl(const std::filesystem::path& pcd);

}  // namespace scanbench::bench
