// Serialized ROS messages into the plain values of io/ros_messages.h, from either wire format: the
// packed little-endian ROS 1 serialization (.bag) or the aligned CDR of ROS 2 (through fastcdr).
// One parser per message type reads both, so the two bag formats decode to the same values.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "semsegmap/io/ros_messages.h"

namespace semsegmap::rosmsg {

enum class WireFormat { kRos1, kCdr };

// A message as the storage hands it over, with what names it in errors.
struct SerializedMessage {
  std::string bytes;
  WireFormat format = WireFormat::kRos1;
  std::filesystem::path file;  // the bag file
  std::string topic;
};

// Each throws std::runtime_error "<file>: truncated <type> message on <topic> (ends inside
// <field>)" when the bytes end early, or names the field that holds an impossible value.
Header parseHeader(const SerializedMessage& m);  // the leading std_msgs/Header of any message
PointCloud2 parsePointCloud2(const SerializedMessage& m);
Image parseImage(const SerializedMessage& m);
CompressedImage parseCompressedImage(const SerializedMessage& m);
CameraInfo parseCameraInfo(const SerializedMessage& m);
Odometry parseOdometry(const SerializedMessage& m);
TfMessage parseTfMessage(const SerializedMessage& m);

// Writing, for the tests' ROS 2 fixtures: the CDR bytes (with the encapsulation header) that a
// ROS 2 publisher of the message would put into a bag. ROS 1 fixtures are written with the ROS 1
// message packages themselves.
std::string toCdr(const PointCloud2& m);
std::string toCdr(const Image& m);
std::string toCdr(const CompressedImage& m);
std::string toCdr(const CameraInfo& m);
std::string toCdr(const Odometry& m);
std::string toCdr(const TfMessage& m);

}  // namespace semsegmap::rosmsg
