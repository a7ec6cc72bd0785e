#include "node_rig.h"

#include <stdexcept>

#include "semsegmap/io/ros_decode.h"
#include "semsegmap/io/rosbag_reader.h"

namespace semsegmap::ros_node {

RigBuilder::RigBuilder(RigTopics topics)
    : topics_(std::move(topics)), infos_(topics_.cameras.size()) {}

void RigBuilder::addScan(const rosmsg::SerializedMessage& scan) {
  if (!scan_) scan_ = rosmsg::parsePointCloud2(scan);
}

void RigBuilder::addCameraInfo(size_t camera, const rosmsg::SerializedMessage& info) {
  if (!infos_.at(camera)) infos_[camera] = rosmsg::parseCameraInfo(info);
}

void RigBuilder::addTransforms(const rosmsg::SerializedMessage& tf, bool is_static) {
  tf_.add(rosmsg::parseTfMessage(tf), is_static);
}

std::optional<DatasetInfo> RigBuilder::rig(std::string& missing) const {
  if (!scan_) {
    missing = "the first scan on " + topics_.lidar;
    return std::nullopt;
  }
  for (size_t c = 0; c < infos_.size(); ++c)
    if (!infos_[c]) {
      missing = "a CameraInfo on " + cameraInfoTopic(topics_.cameras[c]);
      return std::nullopt;
    }
  DatasetInfo info;
  info.name = "ros:" + topics_.lidar;
  const std::string lidar_frame = rosmsg::tfFrameName(scan_->header.frame_id);
  const double t = scan_->header.stamp_s;
  const auto T_base_lidar =
      tf_.lookup(rosmsg::tfFrameName(topics_.base_frame), lidar_frame, t, &missing);
  if (!T_base_lidar) return std::nullopt;
  info.rig.T_base_lidar = *T_base_lidar;
  info.rig.rate_hz = topics_.lidar_rate_hz;
  info.rig.lidar = rosmsg::lidarModelOf(*scan_, rosmsg::decodePointCloud2(*scan_, topics_.lidar));
  for (size_t c = 0; c < infos_.size(); ++c) {
    const std::string& topic = topics_.cameras[c];
    Camera camera = rosmsg::cameraFromInfo(*infos_[c], cameraInfoTopic(topic));
    camera.name = cameraNameOfTopic(topic);
    const auto T =
        tf_.lookup(rosmsg::tfFrameName(infos_[c]->header.frame_id), lidar_frame, t, &missing);
    if (!T) return std::nullopt;
    camera.T_camera_lidar = *T;
    info.rig.cameras.push_back(camera);
  }
  info.rig.validate();
  missing.clear();
  return info;
}

}  // namespace semsegmap::ros_node
