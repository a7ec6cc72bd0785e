#include "semsegmap/io/point_cloud_file.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "semsegmap/io/dataset_format.h"

#if SEMSEGMAP_WITH_PCL
#include <pcl/PCLPointCloud2.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#endif

namespace semsegmap {

namespace fs = std::filesystem;

namespace {

std::string lowerExtension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

#if SEMSEGMAP_WITH_PCL
DecodedPoints decodeCloud(const pcl::PCLPointCloud2& cloud, const fs::path& path) {
  std::vector<PointFieldSpec> fields;
  for (const pcl::PCLPointField& f : cloud.fields)
    fields.push_back({f.name, f.offset, static_cast<FieldType>(f.datatype), f.count});
  const size_t n = static_cast<size_t>(cloud.width) * cloud.height;
  return decodePointFields(fields, cloud.point_step, cloud.data.data(), cloud.data.size(), n,
                           path.string());
}

// PCL prints its own diagnostics and returns a code; the header is read first so that the
// error says what is wrong (a truncated binary file, a point count the data does not hold).
DecodedPoints readPcd(const fs::path& path) {
  pcl::PCDReader reader;
  pcl::PCLPointCloud2 header;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0, data_type = 0;
  unsigned int data_index = 0;
  if (reader.readHeader(path.string(), header, origin, orientation, version, data_type,
                        data_index) < 0)
    throw std::runtime_error(path.string() + ": not a readable PCD header");
  const uint64_t points = static_cast<uint64_t>(header.width) * header.height;
  if (data_type == 1) {  // binary: the size is known up front
    const uint64_t need = data_index + points * header.point_step;
    if (fs::file_size(path) < need)
      throw std::runtime_error(path.string() + ": truncated: the header promises " +
                               std::to_string(points) + " points of " +
                               std::to_string(header.point_step) + " bytes, the file holds " +
                               std::to_string(fs::file_size(path)) + " bytes");
  }
  pcl::PCLPointCloud2 cloud;
  const auto level = pcl::console::getVerbosityLevel();
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);  // our message replaces PCL's
  const int rc = reader.read(path.string(), cloud);
  pcl::console::setVerbosityLevel(level);
  if (rc < 0 || static_cast<uint64_t>(cloud.width) * cloud.height != points)
    throw std::runtime_error(path.string() + ": the data does not hold the " +
                             std::to_string(points) + " points its header declares");
  return decodeCloud(cloud, path);
}

DecodedPoints readPly(const fs::path& path) {
  pcl::PLYReader reader;
  pcl::PCLPointCloud2 cloud;
  const auto level = pcl::console::getVerbosityLevel();
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  const int rc = reader.read(path.string(), cloud);
  pcl::console::setVerbosityLevel(level);
  if (rc < 0) throw std::runtime_error(path.string() + ": not a readable PLY file");
  return decodeCloud(cloud, path);
}
#else
DecodedPoints needsPcl(const fs::path& path) {
  throw std::runtime_error(path.string() +
                           ": PCD and PLY files are read with PCL, which this build left out "
                           "(reconfigure with -DSEMSEGMAP_WITH_PCL=ON)");
}
DecodedPoints readPcd(const fs::path& path) {
  return needsPcl(path);
}
DecodedPoints readPly(const fs::path& path) {
  return needsPcl(path);
}
#endif

}  // namespace

bool isPointCloudFile(const fs::path& path) {
  const std::string ext = lowerExtension(path);
  return ext == ".pcd" || ext == ".ply" || ext == ".bin";
}

DecodedPoints readPointCloudFile(const fs::path& path) {
  if (!fs::is_regular_file(path)) throw std::runtime_error(path.string() + ": no such file");
  const std::string ext = lowerExtension(path);
  if (ext == ".pcd") return readPcd(path);
  if (ext == ".ply") return readPly(path);
  if (ext == ".bin") {
    DecodedPoints d;
    d.points = readLidarBin(path);
    d.intensity_field = "intensity";
    return d;
  }
  throw std::runtime_error(path.string() + ": not a point cloud file (.pcd, .ply or .bin)");
}

}  // namespace semsegmap
