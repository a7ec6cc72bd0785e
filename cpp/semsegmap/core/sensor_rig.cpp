#include "semsegmap/core/sensor_rig.h"

#include <cmath>
#include <stdexcept>
#include <string>

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

CameraModel parseCameraModel(const std::string& name) {
  if (name == "pinhole") return CameraModel::kPinhole;
  if (name == "radtan") return CameraModel::kRadialTangential;
  if (name == "equidistant") return CameraModel::kEquidistant;
  throw std::invalid_argument("unknown camera model '" + name +
                              "' (expected pinhole, radtan or equidistant)");
}

const char* cameraModelName(CameraModel model) {
  switch (model) {
    case CameraModel::kRadialTangential:
      return "radtan";
    case CameraModel::kEquidistant:
      return "equidistant";
    default:
      return "pinhole";
  }
}

// The lens models are written here rather than called from OpenCV because core/ depends on
// the standard library and Eigen only, and enrichment projects every point into every camera
// (a per-point cv::projectPoints call costs more than the arithmetic). The tests compare them
// with OpenCV's cv::projectPoints and cv::fisheye::projectPoints.
namespace {

// d/dr of r * (1 + k1 r^2 + k2 r^4 + k3 r^6) as a polynomial in s = r^2.
double radialSlope(const std::array<double, 5>& k, double s) {
  return 1.0 + s * (3.0 * k[0] + s * (5.0 * k[1] + s * 7.0 * k[4]));
}

// The radial-tangential model is one-to-one from the axis out to radius sqrt(s) when the
// slope stays positive on [0, s]: at s and at the slope's own turning points inside it.
bool radialOneToOne(const std::array<double, 5>& k, double s) {
  if (radialSlope(k, s) <= 0.0) return false;
  // Turning points: 3 k1 + 10 k2 t + 21 k3 t^2 = 0.
  const double a = 21.0 * k[4], b = 10.0 * k[1], c = 3.0 * k[0];
  if (std::abs(a) < 1e-15) {
    const double t = std::abs(b) > 1e-15 ? -c / b : -1.0;
    return !(t > 0.0 && t < s) || radialSlope(k, t) > 0.0;
  }
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return true;
  for (const double t : {(-b - std::sqrt(disc)) / (2.0 * a), (-b + std::sqrt(disc)) / (2.0 * a)})
    if (t > 0.0 && t < s && radialSlope(k, t) <= 0.0) return false;
  return true;
}

// theta_d(theta) = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8).
double fisheyeAngle(const std::array<double, 5>& k, double theta) {
  const double t = theta * theta;
  return theta * (1.0 + t * (k[0] + t * (k[1] + t * (k[2] + t * k[3]))));
}

double fisheyeSlope(const std::array<double, 5>& k, double theta) {
  const double t = theta * theta;
  return 1.0 + t * (3.0 * k[0] + t * (5.0 * k[1] + t * (7.0 * k[2] + t * 9.0 * k[3])));
}

// The fisheye polynomial has no closed-form turning points; its slope is sampled, which is
// exact enough for the smooth calibrations cameras have (theta < 90 degrees here).
bool fisheyeOneToOne(const std::array<double, 5>& k, double theta) {
  for (int i = 1; i <= 8; ++i)
    if (fisheyeSlope(k, theta * i / 8.0) <= 0.0) return false;
  return true;
}

}  // namespace

std::optional<Eigen::Vector2d> Camera::project(const Eigen::Vector3d& p) const {
  if (p.z() <= 1e-6) return std::nullopt;
  // Rectified images keep the arithmetic (and so the rounding) pixels always had.
  if (model == CameraModel::kPinhole)
    return Eigen::Vector2d(fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy);
  const double x = p.x() / p.z(), y = p.y() / p.z();
  const auto& k = distortion;
  double xd = x, yd = y;
  if (model == CameraModel::kRadialTangential) {
    const double r2 = x * x + y * y;
    if (!radialOneToOne(k, r2)) return std::nullopt;
    const double radial = 1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]));
    xd = x * radial + 2.0 * k[2] * x * y + k[3] * (r2 + 2.0 * x * x);
    yd = y * radial + k[2] * (r2 + 2.0 * y * y) + 2.0 * k[3] * x * y;
  } else if (model == CameraModel::kEquidistant) {
    const double r = std::sqrt(x * x + y * y);
    if (r > 1e-12) {
      const double theta = std::atan(r);
      if (!fisheyeOneToOne(k, theta)) return std::nullopt;
      const double scale = fisheyeAngle(k, theta) / r;
      xd = x * scale;
      yd = y * scale;
    }
  }
  return Eigen::Vector2d(fx * xd + cx, fy * yd + cy);
}

Eigen::Vector3d Camera::pixelRay(double u, double v) const {
  const double xd = (u - cx) / fx, yd = (v - cy) / fy;
  double x = xd, y = yd;
  const auto& k = distortion;
  if (model == CameraModel::kRadialTangential) {
    // Fixed-point iteration, as OpenCV's undistortPoints does.
    for (int i = 0; i < 20; ++i) {
      const double r2 = x * x + y * y;
      const double radial = 1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]));
      const double dx = 2.0 * k[2] * x * y + k[3] * (r2 + 2.0 * x * x);
      const double dy = k[2] * (r2 + 2.0 * y * y) + 2.0 * k[3] * x * y;
      x = (xd - dx) / radial;
      y = (yd - dy) / radial;
    }
  } else if (model == CameraModel::kEquidistant) {
    const double theta_d = std::sqrt(xd * xd + yd * yd);
    if (theta_d > 1e-12) {
      double theta = theta_d;  // Newton on theta_d(theta) = theta_d
      for (int i = 0; i < 20; ++i)
        theta -= (fisheyeAngle(k, theta) - theta_d) / fisheyeSlope(k, theta);
      const double scale = std::tan(theta) / theta_d;
      x = xd * scale;
      y = yd * scale;
    }
  }
  return Eigen::Vector3d(x, y, 1.0).normalized();
}

namespace {
bool isFinitePose(const Pose& T) {
  return T.matrix().allFinite();
}
}  // namespace

namespace {

[[noreturn]] void rigFail(const std::string& what) {
  throw std::invalid_argument("sensor rig: " + what);
}

void validateLidar(const LidarModel& lidar) {
  if (lidar.columns <= 0 || lidar.rows <= 0 || lidar.columns > kMaxLidarColumns ||
      lidar.rows > kMaxLidarRows)
    rigFail("lidar.columns and lidar.rows must be in 1.." + std::to_string(kMaxLidarColumns) +
            " and 1.." + std::to_string(kMaxLidarRows));
  if (!(lidar.hfov_deg > 0 && lidar.hfov_deg <= 360)) rigFail("lidar.hfov_deg must be in (0, 360]");
  if (!(lidar.vfov_up_deg > lidar.vfov_down_deg) || !std::isfinite(lidar.vfov_up_deg) ||
      !std::isfinite(lidar.vfov_down_deg))
    rigFail("lidar.vfov_up_deg must exceed vfov_down_deg, both finite");
  if (!(lidar.max_range_m > lidar.min_range_m && lidar.min_range_m >= 0) ||
      !std::isfinite(lidar.max_range_m))
    rigFail("lidar range must satisfy 0 <= min_range_m < max_range_m < infinity");
}

void validateCamera(const Camera& c) {
  const std::string n = "camera '" + c.name + "': ";
  if (c.width <= 0 || c.height <= 0 || c.width > kMaxCameraSide || c.height > kMaxCameraSide)
    rigFail(n + "width and height must be in 1.." + std::to_string(kMaxCameraSide) + ", got " +
            std::to_string(c.width) + " x " + std::to_string(c.height));
  if (!(c.fx > 0 && c.fy > 0) || !std::isfinite(c.fx) || !std::isfinite(c.fy))
    rigFail(n + "focal lengths fx, fy must be positive and finite");
  if (!(c.cx > -c.width && c.cx < 2.0 * c.width && c.cy > -c.height && c.cy < 2.0 * c.height))
    rigFail(n + "principal point (cx, cy) lies far outside the image");
  const Eigen::Matrix3d R = c.T_camera_lidar.linear();
  if (!R.allFinite() || (R * R.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-3 ||
      R.determinant() < 0)
    rigFail(n + "T_camera_lidar rotation is not a proper rotation matrix");
  if (!isFinitePose(c.T_camera_lidar)) rigFail(n + "T_camera_lidar has a NaN or infinite entry");
  for (double d : c.distortion)
    if (!std::isfinite(d)) rigFail(n + "distortion coefficients must be finite");
  if (c.model == CameraModel::kPinhole)
    for (double d : c.distortion)
      if (d != 0.0)
        rigFail(n + "a pinhole camera has no distortion; set model: radtan or equidistant");
  if (c.model == CameraModel::kEquidistant && c.distortion[4] != 0.0)
    rigFail(n + "the equidistant model has four coefficients k1 k2 k3 k4");
}

}  // namespace

void SensorRig::validate() const {
  validateLidar(lidar);
  if (!(rate_hz > 0 && rate_hz <= 1000)) rigFail("rate_hz must be in (0, 1000]");
  if (!isFinitePose(T_base_lidar)) rigFail("T_base_lidar has a NaN or infinite entry");
  const Eigen::Matrix3d R = T_base_lidar.linear();
  if ((R * R.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-3 || R.determinant() < 0)
    rigFail("T_base_lidar rotation is not a proper rotation matrix");
  if (cameras.size() > kMaxCameras)
    rigFail(std::to_string(cameras.size()) + " cameras, at most " + std::to_string(kMaxCameras));
  for (const auto& c : cameras) validateCamera(c);
}

namespace {

LidarModel spinning(int columns, int rows, double hfov_deg, double up_deg, double down_deg) {
  LidarModel m;
  m.columns = columns;
  m.rows = rows;
  m.hfov_deg = hfov_deg;
  m.vfov_up_deg = up_deg;
  m.vfov_down_deg = down_deg;
  return m;
}

}  // namespace

LidarModel velodyneHdl64e() {
  LidarModel m = spinning(2083, 64, 360.0, 2.0, -24.8);  // 0.1728 deg azimuth step at 10 Hz
  m.min_range_m = 0.9;
  m.max_range_m = 120.0;
  m.range_noise_m = 0.02;
  m.dropout = 0.0;  // real scans already carry their dropouts
  return m;
}

// Column counts are the sensors' azimuth steps at 10 Hz, rounded so that the simulator's ray
// budget stays near the paper rig's (a 4500-column HDL-64E would cost 2.3 times as much and
// change no segment: 0.1 m voxels are coarser than its spacing beyond 4 m).
LidarModel lidarPreset(const std::string& name) {
  if (name == "paper") return LidarModel{};
  if (name == "hdl64") {
    // The real sensor's beams with 2048 columns and the simulator's range and dropout defaults,
    // as every simulated HDL-64E result and model so far was rendered.
    const LidarModel real = velodyneHdl64e();
    return spinning(2048, real.rows, real.hfov_deg, real.vfov_up_deg, real.vfov_down_deg);
  }
  if (name == "vlp32") return spinning(1800, 32, 360.0, 15.0, -25.0);
  if (name == "os128") return spinning(1024, 128, 360.0, 22.5, -22.5);
  if (name == "solid") {
    LidarModel m = spinning(600, 96, 70.0, 12.0, -12.0);
    m.max_range_m = 200.0;  // long-range automotive units
    return m;
  }
  throw std::invalid_argument("unknown LiDAR preset '" + name + "' (expected " +
                              lidarPresetNames() + ")");
}

const char* lidarPresetNames() {
  return "paper, hdl64, vlp32, os128, solid";
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
    Camera cam;
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
