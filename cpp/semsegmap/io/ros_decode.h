// ROS messages (io/ros_messages.h, plain values) into the project's types: a PointCloud2 of any
// field layout into LiDAR points and per-point times, Image and CompressedImage into RGB images,
// CameraInfo into a Camera with its lens model, Odometry and transforms into poses. Nothing here
// knows how the message was stored.
#pragma once

#include <string>
#include <vector>

#include "semsegmap/core/frame.h"
#include "semsegmap/core/image.h"
#include "semsegmap/core/sensor_rig.h"
#include "semsegmap/core/stamped_pose.h"
#include "semsegmap/io/ros_messages.h"

namespace semsegmap::rosmsg {

struct DecodedCloud {
  std::vector<LidarPoint> points;
  // Seconds after the header stamp, one per point; empty when the cloud has no time field.
  std::vector<float> point_times;
  size_t dropped_invalid = 0;  // points with a NaN or infinite coordinate (organized clouds)
  int rings = 0;               // 1 + the largest `ring`, 0 without a ring field
};

// The fields: x y z (required, any numeric datatype), intensity or else reflectivity (optional,
// any datatype, value as is; 0 without), ring (optional), and a per-point time, the first of
// `t`, `time`, `timestamp`, `offset_time`. Its unit follows the drivers' conventions: integer
// datatypes count nanoseconds (Ouster's t, Livox's offset_time), floating ones seconds (Velodyne's
// time), except a float beyond 1e15, which is absolute nanoseconds; a time beyond 1e6 s is an
// absolute one (Hesai's timestamp), from which the header stamp is subtracted. Points with a
// non-finite coordinate are dropped and counted. Throws std::runtime_error "<where>: ..." for a
// big-endian cloud, a missing coordinate field, or sizes that do not fit the data.
DecodedCloud decodePointCloud2(const PointCloud2& msg, const std::string& where);

// The LiDAR as one scan shows it: its rings (or the cloud's rows, else 64), the columns they
// give, its vertical extent and range; 360 degrees across, no noise or dropout (a real scan's
// are in its points). What a bag reader or a live node knows of a LiDAR without a rig file.
LidarModel lidarModelOf(const PointCloud2& msg, const DecodedCloud& cloud);

// rgb8, bgr8, rgba8, bgra8, mono8 (grey RGB) and the 8-bit Bayer patterns (bayer_rggb8,
// bayer_bggr8, bayer_gbrg8, bayer_grbg8, demosaiced) into 3-channel RGB. Throws naming the
// encoding otherwise, or when step and data do not fit width and height.
semsegmap::Image decodeImage(const Image& msg, const std::string& where);
// JPEG or PNG (colour or grey) into 3-channel RGB; throws when the bytes do not decode.
semsegmap::Image decodeCompressedImage(const CompressedImage& msg, const std::string& where);

// K and the size; the lens model from distortion_model: plumb_bob (k1 k2 p1 p2 k3; all zero:
// pinhole), rational_polynomial (only when k4 k5 k6 are zero: its first five are plumb_bob),
// equidistant (k1..k4), or none/empty with no coefficients. T_camera_lidar is left identity for
// the caller. Throws "<where>: ..." naming what is refused.
Camera cameraFromInfo(const CameraInfo& msg, const std::string& where);

// Throws std::invalid_argument for a zero or non-finite quaternion or translation.
Pose poseOf(const Transform& t);
StampedPose stampedPoseOf(const Odometry& msg);

}  // namespace semsegmap::rosmsg
