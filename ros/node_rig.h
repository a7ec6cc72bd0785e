// What the node must know before its first frame: the rig, from the topics and TF as the bag
// reader finds it in a bag (io/rosbag_reader.h), and the messages that came while it waited.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/io/ros_serialization.h"
#include "semsegmap/io/ros_tf.h"

namespace semsegmap::ros_node {

struct RigTopics {
  std::string lidar;                 // sensor_msgs/PointCloud2
  std::vector<std::string> cameras;  // Image or CompressedImage, CameraInfo at <ns>/camera_info
  std::string base_frame = "base_link";
  double lidar_rate_hz = 10.0;
};

// Collects the first scan, each camera's first CameraInfo and the transforms, and makes the
// DatasetInfo once all are there.
class RigBuilder {
 public:
  explicit RigBuilder(RigTopics topics);
  void addScan(const rosmsg::SerializedMessage& scan);
  void addCameraInfo(size_t camera, const rosmsg::SerializedMessage& info);
  void addTransforms(const rosmsg::SerializedMessage& tf, bool is_static);
  // The rig, once the scan, every CameraInfo and the transforms between their frames are
  // there; nothing before, `missing` then says what is awaited. Throws std::runtime_error for
  // a message that does not decode or a camera whose CameraInfo is refused.
  std::optional<DatasetInfo> rig(std::string& missing) const;

 private:
  RigTopics topics_;
  std::optional<rosmsg::PointCloud2> scan_;
  std::vector<std::optional<rosmsg::CameraInfo>> infos_;
  rosmsg::TfBuffer tf_;
};

}  // namespace semsegmap::ros_node
