#include "semsegmap/core/sensor_rig.h"

#include <cmath>
#include <stdexcept>

namespace semsegmap {

Eigen::Vector3d LidarModel::beamDirection(int row, int col) const {
  const double deg = M_PI / 180.0;
  // Columns sweep from +hfov/2 (left) to -hfov/2 (right), like a clockwise-spinning sensor.
  const double azimuth = (0.5 * hfov_deg - (col + 0.5) * hfov_deg / columns) * deg;
  const double elevation =
      (vfov_up_deg - (rows > 1 ? row * (vfov_up_deg - vfov_down_deg) / (rows - 1) : 0.0)) * deg;
  return {std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
          std::sin(elevation)};
}

std::optional<Eigen::Vector2d> PinholeCamera::project(const Eigen::Vector3d& p) const {
  if (p.z() <= 1e-6) return std::nullopt;
  return Eigen::Vector2d(fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy);
}

Eigen::Vector3d PinholeCamera::pixelRay(double u, double v) const {
  return Eigen::Vector3d((u - cx) / fx, (v - cy) / fy, 1.0).normalized();
}

void SensorRig::validate() const {
  auto fail = [](const std::string& what) { throw std::invalid_argument("sensor rig: " + what); };
  if (lidar.columns <= 0 || lidar.rows <= 0) fail("lidar.columns and lidar.rows must be positive");
  if (!(lidar.hfov_deg > 0 && lidar.hfov_deg <= 360)) fail("lidar.hfov_deg must be in (0, 360]");
  if (!(lidar.vfov_up_deg > lidar.vfov_down_deg))
    fail("lidar.vfov_up_deg must exceed vfov_down_deg");
  if (!(lidar.max_range_m > lidar.min_range_m && lidar.min_range_m >= 0))
    fail("lidar range must satisfy 0 <= min_range_m < max_range_m");
  if (!(rate_hz > 0)) fail("rate_hz must be positive");
  for (const auto& c : cameras) {
    const std::string n = "camera '" + c.name + "': ";
    if (c.width <= 0 || c.height <= 0) fail(n + "width and height must be positive");
    if (!(c.fx > 0 && c.fy > 0) || !std::isfinite(c.fx) || !std::isfinite(c.fy))
      fail(n + "focal lengths fx, fy must be positive and finite");
    if (!(c.cx > -c.width && c.cx < 2.0 * c.width && c.cy > -c.height && c.cy < 2.0 * c.height))
      fail(n + "principal point (cx, cy) lies far outside the image");
    const Eigen::Matrix3d R = c.T_camera_lidar.linear();
    if (!R.allFinite() || (R * R.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-3 ||
        R.determinant() < 0)
      fail(n + "T_camera_lidar rotation is not a proper rotation matrix");
  }
}

SensorRig defaultSimRig() {
  SensorRig rig;
  // Base frame: x forward, y left, z up, on the ground below the LiDAR.
  rig.T_base_lidar = Pose::Identity();
  rig.T_base_lidar.translation() = Eigen::Vector3d(0.0, 0.0, 1.9);

  // Camera optical axes (z) point forward, left and right; x right and y down in the image.
  struct Mount {
    const char* name;
    double yaw_deg;
    Eigen::Vector3d offset_in_lidar;
  };
  const Mount mounts[] = {{"left", 90.0, {0.05, 0.30, -0.20}},
                          {"front", 0.0, {0.35, 0.0, -0.25}},
                          {"right", -90.0, {0.05, -0.30, -0.20}}};
  for (const auto& m : mounts) {
    PinholeCamera cam;
    cam.name = m.name;
    cam.width = 640;
    cam.height = 480;
    cam.fx = cam.fy = 320.0;  // 90 degrees horizontal field of view
    cam.cx = 320.0;
    cam.cy = 240.0;
    // Rotation from the camera's optical frame to the LiDAR frame for a camera looking along yaw.
    const double y = m.yaw_deg * M_PI / 180.0;
    const Eigen::Vector3d z_axis(std::cos(y), std::sin(y), 0.0);   // forward
    const Eigen::Vector3d x_axis(std::sin(y), -std::cos(y), 0.0);  // right
    const Eigen::Vector3d y_axis(0.0, 0.0, -1.0);                  // down
    Pose T_lidar_camera = Pose::Identity();
    T_lidar_camera.linear().col(0) = x_axis;
    T_lidar_camera.linear().col(1) = y_axis;
    T_lidar_camera.linear().col(2) = z_axis;
    T_lidar_camera.translation() = m.offset_in_lidar;
    cam.T_camera_lidar = T_lidar_camera.inverse();
    rig.cameras.push_back(cam);
  }
  return rig;
}

}  // namespace semsegmap
