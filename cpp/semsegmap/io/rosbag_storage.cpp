#include "semsegmap/io/rosbag_storage.h"

#include <stdexcept>

namespace semsegmap::rosmsg {

std::string normaliseTypeName(const std::string& type) {
  const std::string infix = "/msg/";
  const size_t at = type.find(infix);
  if (at == std::string::npos) return type;
  return type.substr(0, at) + "/" + type.substr(at + infix.size());
}

std::unique_ptr<BagStorage> openBagStorage(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec))
    throw std::runtime_error(path.string() + ": no such bag file or folder");
  if (fs::is_directory(path, ec)) return openRos2Bag(path);
  const std::string ext = path.extension().string();
  if (ext == ".bag") return openRos1Bag(path);
  if (ext == ".db3") return openRos2Bag(path);
  if (ext == ".mcap") return openMcapBag(path);
  throw std::runtime_error(
      path.string() +
      ": not a bag (expected a ROS 1 .bag, a ROS 2 .db3, an .mcap or a ROS 2 bag folder)");
}

#if !SEMSEGMAP_WITH_ROS1
std::unique_ptr<BagStorage> openRos1Bag(const std::filesystem::path& bag_file) {
  throw std::runtime_error(bag_file.string() +
                           ": this build reads no ROS 1 bags (built with SEMSEGMAP_WITH_ROS1=OFF)");
}
#endif

}  // namespace semsegmap::rosmsg
