#include "bench/pcl_io.hpp"

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>

#include <stdexcept>

namespace scanbench::bench {

std::size_t read_pcd_blob_with_pcl(const std::filesystem::path& pcd) {
  pcl::PCLPointCloud2 cloud;
  pcl::PCDReader reader;
  if (reader.read(pcd.string(), cloud) != 0) {
    throw std::runtime_error(pcd.string() + ": PCL could not read the file");
  }
  return static_cast<std::size_t>(cloud.width) * cloud.height;
}

std::size_t read_pcd_xyzi_with_pcl(const std::filesystem::path& pcd) {
  pcl::PointCloud<pcl::PointXYZI> cloud;
  if (pcl::io::loadPCDFile(pcd.string(), cloud) != 0) {
    throw std::runtime_error(pcd.string() + ": PCL could not read the file");
  }
  return cloud.size();
}

void write_binary_pcd_with_pcl(const std::filesystem::path& pcd, std::span<const float> xyzi,
                               int width, int height) {
  pcl::PointCloud<pcl::PointXYZI> cloud(static_cast<std::uint32_t>(width),
                                        static_cast<std::uint32_t>(height));
  cloud.is_dense = false;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    pcl::PointXYZI& p = cloud[i];
    p.x = xyzi[4 * i];
    p.y = xyzi[4 * i + 1];
    p.z = xyzi[4 * i + 2];
    p.intensity = xyzi[4 * i + 3];
  }
  if (pcl::io::savePCDFileBinary(pcd.string(), cloud) != 0) {
    throw std::runtime_error(pcd.string() + ": PCL could not write the file");
  }
}

}  // namespace scanbench::bench
