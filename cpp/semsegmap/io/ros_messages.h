// The ROS messages the bag reader uses, as plain values: the fields of sensor_msgs, nav_msgs and
// tf2_msgs that matter here, the same for ROS 1 and ROS 2. Storage (ROS 1 .bag, ROS 2 sqlite)
// and wire encoding (ROS 1 serialization, CDR) end here; decoding into frames
// (io/ros_decode.h) starts here and needs no ROS library.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace semsegmap::rosmsg {

// The type names as ROS 1 spells them; ROS 2's "sensor_msgs/msg/PointCloud2" is normalised to
// this form when a bag is opened.
inline constexpr const char* kPointCloud2 = "sensor_msgs/PointCloud2";
inline constexpr const char* kImage = "sensor_msgs/Image";
inline constexpr const char* kCompressedImage = "sensor_msgs/CompressedImage";
inline constexpr const char* kCameraInfo = "sensor_msgs/CameraInfo";
inline constexpr const char* kOdometry = "nav_msgs/Odometry";
inline constexpr const char* kTfMessage = "tf2_msgs/TFMessage";

struct Header {
  double stamp_s = 0.0;  // seconds since the epoch (sec + nanosec * 1e-9)
  std::string frame_id;
};

// sensor_msgs/PointField. `datatype` is kept as read: its numbering is FieldType's
// (io/point_fields.h), which checks it when the points are decoded.
struct PointField {
  std::string name;
  uint32_t offset = 0;
  uint8_t datatype = 0;
  uint32_t count = 1;
};

struct PointCloud2 {
  Header header;
  uint32_t height = 0, width = 0;
  std::vector<PointField> fields;
  bool is_bigendian = false;
  uint32_t point_step = 0, row_step = 0;
  std::vector<uint8_t> data;
  bool is_dense = false;
};

struct Image {
  Header header;
  uint32_t height = 0, width = 0;
  std::string encoding;  // "rgb8", "bgr8", "mono8", "bayer_rggb8", ...
  uint8_t is_bigendian = 0;
  uint32_t step = 0;  // bytes per row
  std::vector<uint8_t> data;
};

struct CompressedImage {
  Header header;
  std::string format;  // "jpeg", "png", or image_transport's "rgb8; jpeg compressed bgr8"
  std::vector<uint8_t> data;
};

struct CameraInfo {
  Header header;
  uint32_t height = 0, width = 0;
  std::string distortion_model;  // "plumb_bob", "rational_polynomial", "equidistant", ""
  std::vector<double> D;
  std::array<double, 9> K{};  // row-major 3x3
};

// A rigid transform: translation and unit quaternion (x y z w), as geometry_msgs spells it.
struct Transform {
  std::array<double, 3> translation{};
  std::array<double, 4> rotation{0, 0, 0, 1};
};

// nav_msgs/Odometry: the pose of child_frame_id in header.frame_id.
struct Odometry {
  Header header;
  std::string child_frame_id;
  Transform pose;
};

// geometry_msgs/TransformStamped: maps points of child_frame_id into header.frame_id.
struct TransformStamped {
  Header header;
  std::string child_frame_id;
  Transform transform;
};

struct TfMessage {
  std::vector<TransformStamped> transforms;
};

}  // namespace semsegmap::rosmsg
