// The sensor rig: a LiDAR and cameras, with the calibrations that the
// enrichment needs (intrinsics, LiDAR-to-camera extrinsics) and the LiDAR mounting on the base.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/pose.h"

namespace semsegmap {

struct LidarModel {
  int columns = 1920;        // horizontal beams per revolution of the field of view
  int rows = 64;             // vertical beams
  double hfov_deg = 270.0;   // centred on the LiDAR's +x (forward)
  double vfov_up_deg = 2.0;  // HDL-64-like vertical field of view
  double vfov_down_deg = -24.8;
  double min_range_m = 0.9;
  double max_range_m = 100.0;
  double range_noise_m = 0.02;  // Gaussian sigma
  double dropout = 0.01;        // probability that a return is lost

  // Unit direction of beam (row, col) in the LiDAR frame; row 0 is the top beam.
  Eigen::Vector3d beamDirection(int row, int col) const;
};

// How a camera's lens bends rays: none (rectified images), OpenCV's radial-tangential model
// (k1 k2 p1 p2 k3) or the equidistant fisheye model of OpenCV's fisheye module (k1 k2 k3 k4).
enum class CameraModel { kPinhole, kRadialTangential, kEquidistant };

// "pinhole" | "radtan" | "equidistant"; throws std::invalid_argument naming the alternatives.
CameraModel parseCameraModel(const std::string& name);
const char* cameraModelName(CameraModel model);

// A camera in the OpenCV convention (x right, y down, z forward). T_camera_lidar maps LiDAR
// points into the camera frame. Points are projected through the lens model, so distorted
// images are used as recorded.
struct Camera {
  std::string name;
  int width = 640;
  int height = 480;
  double fx = 320.0, fy = 320.0, cx = 320.0, cy = 240.0;
  CameraModel model = CameraModel::kPinhole;
  // radtan: k1 k2 p1 p2 k3; equidistant: k1 k2 k3 k4 (the fifth is 0); pinhole: all 0.
  std::array<double, 5> distortion{};
  Pose T_camera_lidar = Pose::Identity();

  // Pixel of a point given in the camera frame, or nothing when it is behind the camera or
  // outside the range where the lens model is one-to-one (a polynomial folds back there, and
  // a far-off-axis point would land on a wrong pixel).
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& p_camera) const;
  // Unit ray through pixel (u, v) in the camera frame (the lens model inverted iteratively).
  Eigen::Vector3d pixelRay(double u, double v) const;
  bool inImage(const Eigen::Vector2d& uv) const {
    return uv.x() >= 0 && uv.y() >= 0 && uv.x() < width && uv.y() < height;
  }
};

// What a rig can have, checked by validate(): a rig read from a file larger than this is corrupt,
// and its images or range images would be allocated whole (a 40000 x 40000 camera is 6 GB of
// z-buffers a frame).
constexpr int kMaxCameraSide = 16384;
constexpr size_t kMaxCameras = 64;
constexpr int kMaxLidarColumns = 1 << 16;
constexpr int kMaxLidarRows = 1024;

struct SensorRig {
  LidarModel lidar;
  Pose T_base_lidar = Pose::Identity();
  std::vector<Camera> cameras;
  double rate_hz = 5.0;

  // Throws std::invalid_argument naming the field when the rig cannot be right
  // (sizes outside the limits above, non-positive or non-finite focal lengths, a principal point
  // far outside the image, a non-finite pose or extrinsic, ...).
  void validate() const;
};

// The paper's simulated rig: LiDAR 1920 x 64 over 270 degrees, three 90-degree cameras
// (left, front, right) at 640 x 480, mounted with a few decimetres of parallax.
SensorRig defaultSimRig();

// The Velodyne HDL-64E as its recordings are (datasheet values at 10 Hz: 2083 columns, 64 rows,
// +2 to -24.8 degrees, 0.9-120 m): the LiDAR of the readers of real KITTI data, and the beams of
// the simulator's `hdl64` preset.
LidarModel velodyneHdl64e();

// Beam patterns of common real LiDARs, so that the simulator can render what they see and
// descriptors can be trained on more than one sensor:
//   paper  1920 x 64 over 270 degrees, +2 to -24.8 (the default; the paper's rig)
//   hdl64  Velodyne HDL-64E as in KITTI (velodyneHdl64e's beams, 2048 of its 2083 columns)
//   vlp32  a 32-beam spinning LiDAR (VLP-32C-like): 1800 x 32 over 360 degrees, +15 to -25
//   os128  a 128-beam spinning LiDAR (OS1-128-like): 1024 x 128 over 360 degrees, +22.5 to -22.5
//   solid  a forward-looking solid-state LiDAR: 600 x 96 over 70 degrees, +12 to -12
// Throws std::invalid_argument naming the presets for any other name.
LidarModel lidarPreset(const std::string& name);
const char* lidarPresetNames();  // "paper, hdl64, vlp32, os128, solid"

}  // namespace semsegmap
