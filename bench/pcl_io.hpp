// PCL's own PCD reader and writer, the peer of our PCD reader in `bench io`.
// The header exposes no PCL type; PCL stays in pcl_io.cpp.
#pragma once

#include <cstddef>
#include <filesystem>
#include <span>

namespace scanbench::bench {

// Reads `pcd` with pcl::PCDReader into a PCLPointCloud2 (PCL's untyped
// blob, the least work PCL can do) and returns its point count. Throws
// std::runtime_error naming the file when PCL fails.
std::size_t read_pcd_blob_with_pcl(const std::filesystem::path& pcd);

// Reads `pcd` with pcl::io::loadPCDFile into a pcl::PointCloud<PointXYZI>,
// a cloud a program can use (what our reader's Scan is), and returns its
// point count. Throws std::runtime_error naming the file when PCL fails.
std::size_t read_pcd_xyzi_with_pcl(const std::filesystem::path& pcd);

// Writes an organized width × height cloud of x y z intensity floats (4 per
// point, row-major; NaN x for no return) as a binary PCD with PCL's writer.
void write_binary_pcd_with_pcl(const std::filesystem::path& pcd, std::span<const float> xyzi,
                               int width, int height);

}  // namespace scanbench::bench
