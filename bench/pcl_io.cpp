#include "bench/pcl_io.hpp"

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <stdexcept>

namespace scanbench::bench {

std::size_t read_pcd_with_pcl(const std::filesystem::path& pcd) {
  pcl::PCLPointCloud2 cloud;
  pcl::PCDReader reader;
  if (reader.read(pcd.string(), cloud) != 0) {
    throw std::runtime_error(pcd.string() + ": PCL could not read the file");
  }
  return static_cast<std::size_t>(cloud.width) * cloud.height;
}

}  // namespace scanbench::bench
