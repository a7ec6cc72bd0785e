// A ROS bag as a dataset (`--dataset rosbag:PATH[,key=value...]`): ROS 1 .bag files, ROS 2 bags
// in sqlite3 (a .db3 file or a bag folder). One frame per LiDAR message; each camera's nearest
// image within a tolerance; calibration from CameraInfo and the TF tree; odometry from an
// Odometry topic or from TF.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/core/pose.h"

namespace semsegmap {

namespace rosmsg {
class BagStorage;
class TfBuffer;
}  // namespace rosmsg

// What the bag does not say by itself. Everything has a default that finds it by type.
struct RosbagOptions {
  // The LiDAR's sensor_msgs/PointCloud2 topic; empty: the bag's only one (several: an error that
  // lists them).
  std::string lidar_topic;
  // The cameras' Image or CompressedImage topics, each with a CameraInfo beside it
  // (".../image_raw" and ".../camera_info"; ".../image_raw/compressed" likewise). Unset: every
  // image topic of the bag (a raw and a compressed topic of one camera count once, the raw one);
  // empty (camera=none): no camera.
  std::optional<std::vector<std::string>> camera_topics;
  // A nav_msgs/Odometry topic; empty: the bag's only one, else the TF chain odom_frame ->
  // base_frame, else none (DatasetInfo::has_odometry is false).
  std::string odometry_topic;
  // The robot's frame; empty: base_link when TF has it, else the LiDAR's own frame.
  std::string base_frame;
  std::string odom_frame = "odom";
  // How far an image may be from its scan; unset: half the LiDAR period.
  std::optional<double> tolerance_s;
};

// The options part of a spec, "lidar=/points,camera=/a/image_raw;/b/image_raw,tolerance=0.05"
// (keys lidar, camera, odometry, base_frame, odom_frame, tolerance; an empty text gives the
// defaults). Throws std::invalid_argument, one line naming the key, for an unknown or repeated
// key, a missing '=' or value, or a tolerance that is not a positive number.
RosbagOptions parseRosbagOptions(const std::string& text);

// The CameraInfo topic beside an image topic: ".../image_raw" and ".../image_raw/compressed"
// both have theirs at ".../camera_info".
std::string cameraInfoTopic(const std::string& image_topic);
// A camera's name from its image topic: the namespace without its leading '/'
// ("/kitti/camera_left/image_raw" -> "kitti/camera_left"), or the topic when it has none.
std::string cameraNameOfTopic(const std::string& image_topic);

class RosbagReader : public FrameSource {
 public:
  // Opens the bag and indexes it: the topics, each message's place and header stamp, the TF
  // tree, CameraInfo and odometry (all small); scans and images are decoded in frame(). The
  // header stamps cost a read of each scan and image once (sqlite reads only their first bytes;
  // rosbag and MCAP chunks read whole messages), never more than one message in memory. Throws
  // std::runtime_error, one line naming the bag file and the topic or transform, when something
  // needed is missing or the bag is corrupt. Notes (the base frame taken to be the LiDAR, scans
  // without an image, scans outside the odometry) go to stderr once.
  RosbagReader(const std::filesystem::path& bag, RosbagOptions options = {});
  ~RosbagReader() override;

  const DatasetInfo& info() const override { return info_; }
  size_t size() const override { return scans_.size(); }
  // Decodes scan `index` and its images. Throws std::out_of_range past the end, and
  // std::runtime_error naming the file and topic for a message that does not decode.
  Frame frame(size_t index) override;
  double frameTime(size_t index) override;  // from the index, without decoding the scan

  const std::string& lidarTopic() const { return lidar_topic_; }
  std::vector<std::string> cameraTopics() const;

 private:
  struct Stream;  // a topic's messages: where they are and their header stamps
  struct CameraStream;

  void chooseLidar();
  void chooseCameras();
  void addCamera(const std::string& image_topic);
  void readTransforms();
  void findBaseFrame();
  void findOdometry();
  std::vector<std::optional<Pose>> odometryFromTopic(const std::string& topic);
  void keepFramesWithOdometry(const std::vector<std::optional<Pose>>& poses);
  void associateImages();
  void describeLidar();
  Stream indexTopic(const std::string& topic, bool need_messages);
  [[noreturn]] void fail(const std::string& what) const;
  void note(const std::string& what) const;

  std::filesystem::path path_;
  RosbagOptions options_;
  std::unique_ptr<rosmsg::BagStorage> bag_;
  DatasetInfo info_;
  std::string lidar_topic_, lidar_frame_, base_frame_;
  std::unique_ptr<Stream> scans_all_;
  std::vector<size_t> scans_;      // the scans that are frames, as indices into *scans_all_
  std::vector<Pose> T_odom_base_;  // per frame, when the bag has odometry
  std::vector<CameraStream> cameras_;
  std::unique_ptr<rosmsg::TfBuffer> tf_;
};

}  // namespace semsegmap
