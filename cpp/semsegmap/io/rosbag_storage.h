// The storage of a bag: its topics, the messages of a topic (receive time and where each is), and
// a message's serialized bytes on demand. ROS 1 .bag files (rosbag_storage, when the build has
// SEMSEGMAP_WITH_ROS1), ROS 2 bags in sqlite3 (a .db3 file or a bag folder with metadata.yaml;
// CDR messages) and MCAP files (.mcap, alone or in a bag folder). Nothing is decoded here:
// io/ros_serialization.h does that.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "semsegmap/io/ros_serialization.h"

namespace semsegmap::rosmsg {

struct BagTopic {
  std::string name;
  std::string type;  // normalised to the ROS 1 spelling, "sensor_msgs/PointCloud2"
  size_t count = 0;  // messages
};

// Where a message is; only the storage that handed it out can read it.
struct MessageRef {
  double time_s = 0.0;  // when the recorder received it
  size_t file = 0;      // which file of a split bag
  int64_t row = 0;      // the message within it
};

class BagStorage {
 public:
  virtual ~BagStorage() = default;
  // The file named in errors: the .bag or .db3 (the first one of a split ROS 2 bag).
  virtual const std::filesystem::path& path() const = 0;
  virtual const std::vector<BagTopic>& topics() const = 0;
  // The messages of a topic in receive order. Throws naming the file when the topic's messages
  // are not readable (a corrupt bag, a ROS 2 serialization other than cdr).
  virtual std::vector<MessageRef> messages(const std::string& topic) = 0;
  // Throws std::runtime_error naming the file when the message cannot be read.
  virtual SerializedMessage read(const std::string& topic, const MessageRef& ref) = 0;
  // At least the first `max_bytes` of a message (all of it when shorter): enough for its header.
  // Storages that cannot read part of a message read all of it.
  virtual SerializedMessage readPrefix(const std::string& topic, const MessageRef& ref,
                                       size_t max_bytes) {
    (void)max_bytes;
    return read(topic, ref);
  }
};

// By what `path` is: a file ending in .bag (ROS 1), .db3 or .mcap, or a folder holding a ROS 2
// bag (metadata.yaml and .db3 files, or one .mcap file). Throws std::runtime_error, one line naming
// the path, when it is none of these, is missing, or is not readable as what it claims to be (a
// corrupt or truncated bag, a compressed or split MCAP ROS 2 bag, a ROS 1 bag in a build without
// ROS 1).
std::unique_ptr<BagStorage> openBagStorage(const std::filesystem::path& path);

// The storages behind openBagStorage.
std::unique_ptr<BagStorage> openRos1Bag(const std::filesystem::path& bag_file);
std::unique_ptr<BagStorage> openRos2Bag(const std::filesystem::path& db3_or_folder);
// One .mcap file (zstd, lz4 or uncompressed chunks; cdr or ros1 messages).
std::unique_ptr<BagStorage> openMcapBag(const std::filesystem::path& mcap_file);

// "sensor_msgs/msg/Image" -> "sensor_msgs/Image"; ROS 1 names are returned as they are.
std::string normaliseTypeName(const std::string& type);

}  // namespace semsegmap::rosmsg
