#include "semsegmap/io/kitti_raw_reader.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "semsegmap/io/dataset_format.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/io/kitti_calib.h"

namespace semsegmap {
namespace fs = std::filesystem;
namespace {

fs::path normalizedDir(const fs::path& p) {
  fs::path dir = fs::absolute(p).lexically_normal();
  if (dir.filename().empty()) dir = dir.parent_path();  // "drive/" names the same folder
  return dir;
}

// KITTI ships one set of calibration files per recording day, next to that day's drives.
fs::path findCalibration(const fs::path& drive_dir, const std::string& name) {
  const fs::path one_up = drive_dir.parent_path() / name;
  const fs::path two_up = drive_dir.parent_path().parent_path() / name;
  if (fs::is_regular_file(one_up)) return one_up;
  if (fs::is_regular_file(two_up)) return two_up;
  throw std::runtime_error(one_up.string() + ": calibration file not found (nor in " +
                           two_up.parent_path().string() + ")");
}

int64_t daysFromCivil(int64_t y, int m, int d) {
  // Howard Hinnant's proleptic Gregorian day count, 1970-01-01 = 0.
  y -= m <= 2;
  const int64_t era = (y >= 0 ? y : y - 399) / 400;
  const int64_t yoe = y - era * 400;
  const int64_t doy = (153 * (m > 2 ? m - 3 : m + 9) + 2) / 5 + d - 1;
  const int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

// "2011-09-26 13:02:25.964389445" -> seconds since the Unix epoch. KITTI logs local clock time
// without a zone; it is read as UTC, which only shifts all frames by the same constant.
std::vector<double> readTimestamps(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  std::vector<double> times;
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    int y = 0, mo = 0, d = 0, h = 0, mi = 0, consumed = 0;
    double s = 0.0;
    const int n =
        std::sscanf(line.c_str(), "%d-%d-%d %d:%d:%lf%n", &y, &mo, &d, &h, &mi, &s, &consumed);
    const bool rest_blank =
        n == 6 && line.find_first_not_of(" \t\r", static_cast<size_t>(consumed)) == line.npos;
    if (!rest_blank || mo < 1 || mo > 12 || d < 1 || d > 31 || h < 0 || h > 23 || mi < 0 ||
        mi > 59 || !(s >= 0 && s < 61))
      throw std::runtime_error(path.string() + ": line " + std::to_string(line_no) +
                               ": expected 'YYYY-MM-DD hh:mm:ss.fraction'");
    times.push_back(static_cast<double>(daysFromCivil(y, mo, d)) * 86400.0 + h * 3600.0 +
                    mi * 60.0 + s);
  }
  return times;
}

// The devkit's rotation of an oxts record: heading about z, then pitch about y, roll about x.
Eigen::Matrix3d rotationRpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

std::vector<double> readOxts(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open oxts record");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<double> v;
  try {
    v = parseNumbers(text);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path.string() + ": " + e.what());
  }
  if (v.size() != 30)
    throw std::runtime_error(path.string() + ": expected 30 oxts values, found " +
                             std::to_string(v.size()));
  if (!(std::abs(v[0]) < 90.0 && std::abs(v[1]) <= 180.0))
    throw std::runtime_error(path.string() + ": latitude/longitude out of range");
  return v;
}

}  // namespace

KittiRawReader::KittiRawReader(const fs::path& drive_dir) : dir_(normalizedDir(drive_dir)) {
  const fs::path scan_dir = dir_ / "velodyne_points" / "data";
  if (!fs::is_directory(scan_dir))
    throw std::runtime_error(scan_dir.string() + ": missing (not a KITTI raw drive folder)");
  const auto scans = listKittiFrames(scan_dir, ".bin");
  if (scans.empty()) throw std::runtime_error(scan_dir.string() + ": no .bin scans");

  cam_to_cam_path_ = findCalibration(dir_, "calib_cam_to_cam.txt");
  const KittiCalibFile cam_to_cam(cam_to_cam_path_);
  const KittiCalibFile velo_to_cam(findCalibration(dir_, "calib_velo_to_cam.txt"));

  info_.name = "kitti-raw:" + dir_.filename().string();
  info_.rig.lidar = velodyneHdl64e();
  // KITTI's base frame is the Velodyne itself (x forward, y left, z up): poses and odometry
  // below are LiDAR poses, so the mounting is identity.
  info_.rig.T_base_lidar = Pose::Identity();
  info_.rig.cameras = {kittiRectifiedCamera(cam_to_cam, velo_to_cam, 2)};
  info_.rig.rate_hz = 10.0;
  try {
    info_.rig.validate();
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(cam_to_cam_path_.string() + ": " + e.what());
  }
  info_.classes = ClassTable::Default();
  info_.has_point_labels = false;

  const fs::path times_path = dir_ / "velodyne_points" / "timestamps.txt";
  const bool has_times = fs::exists(times_path);
  const std::vector<double> times = has_times ? readTimestamps(times_path) : std::vector<double>{};
  const fs::path oxts_dir = dir_ / "oxts" / "data";
  has_oxts_ = fs::is_directory(oxts_dir);

  for (const auto& [number, scan] : scans) {
    FrameFiles f;
    f.scan = scan;
    f.number = number;
    f.image = dir_ / "image_02" / "data" / (scan.stem().string() + ".png");
    if (!fs::is_regular_file(f.image))
      throw std::runtime_error(f.image.string() + ": missing (the image of scan " + scan.string() +
                               ")");
    if (has_oxts_) {
      f.oxts = oxts_dir / (scan.stem().string() + ".txt");
      if (!fs::is_regular_file(f.oxts))
        throw std::runtime_error(f.oxts.string() + ": missing (the oxts record of scan " +
                                 scan.string() + ")");
    }
    f.timestamp_s =
        kittiScanTime(has_times ? &times : nullptr, times_path, number, info_.rig.rate_hz);
    frames_.push_back(f);
  }

  info_.origin.kind = "kitti-raw";
  info_.origin.lidar = "velodyne_points/data/*.bin";
  info_.origin.cameras = {"image_02/data/*.png, calibration " + cam_to_cam_path_.string()};
  if (has_oxts_) info_.origin.odometry = info_.origin.ground_truth = "oxts/data (GPS/INS)";
  info_.has_ground_truth_poses = has_oxts_;
  info_.has_odometry = has_oxts_;  // the oxts poses serve as odometry too
  info_.odometry_is_ground_truth = has_oxts_;
  info_.has_frame_times = has_times;
  if (has_oxts_) {
    // oxts poses are IMU poses; the LiDAR pose needs the IMU-to-Velodyne mounting.
    const KittiCalibFile imu_to_velo(findCalibration(dir_, "calib_imu_to_velo.txt"));
    Pose T_lidar_imu = imu_to_velo.transform("R", "T");
    T_lidar_imu.linear() = nearestRotation(T_lidar_imu.linear());
    T_imu_lidar_ = T_lidar_imu.inverse();
    const std::vector<double> first = readOxts(frames_.front().oxts);
    mercator_scale_ = std::cos(first[0] * M_PI / 180.0);
    T_world_mercator_ = Pose::Identity();  // so that oxtsPose gives T_mercator_lidar here
    T_world_mercator_ = oxtsPose(frames_.front().oxts).inverse();
  }
}

// Pose of the LiDAR in the world frame (the first frame's LiDAR), from one oxts record with the
// devkit's convertOxtsToPose: Mercator x/y scaled by the first latitude, altitude as z.
Pose KittiRawReader::oxtsPose(const fs::path& oxts_file) const {
  const std::vector<double> v = readOxts(oxts_file);
  const double lat = v[0], lon = v[1], alt = v[2];
  const double earth_radius_m = 6378137.0;
  Pose T_mercator_imu = Pose::Identity();
  T_mercator_imu.translation() = Eigen::Vector3d(
      mercator_scale_ * lon * M_PI * earth_radius_m / 180.0,
      mercator_scale_ * earth_radius_m * std::log(std::tan((90.0 + lat) * M_PI / 360.0)), alt);
  T_mercator_imu.linear() = rotationRpy(v[3], v[4], v[5]);
  return T_world_mercator_ * T_mercator_imu * T_imu_lidar_;
}

Frame KittiRawReader::frame(size_t index) {
  if (index >= frames_.size()) throwFrameOutOfRange(info_.name, index, frames_.size());
  const FrameFiles& files = frames_[index];
  Frame f = kittiScanFrame(index, files.timestamp_s, files.scan);
  f.number = files.number;

  Image rgb = readPng(files.image);
  const Camera& cam = info_.rig.cameras.front();
  if (rgb.channels != 3)
    throw std::runtime_error(files.image.string() + ": expected a 3-channel color image, found " +
                             std::to_string(rgb.channels) + " channel(s)");
  if (rgb.width != cam.width || rgb.height != cam.height)
    throw std::runtime_error(
        files.image.string() + ": image is " + imageSizeText(rgb.width, rgb.height) + " but " +
        cam_to_cam_path_.string() + ": S_rect_02 says " + imageSizeText(cam.width, cam.height));
  f.cameras.push_back(CameraFrame{std::move(rgb), Image(), std::nullopt});

  if (has_oxts_) {
    const Pose T_world_lidar = oxtsPose(files.oxts);
    f.T_world_base = T_world_lidar;
    f.T_odom_base = T_world_lidar;  // KITTI raw has no separate odometry
  }
  return f;
}

}  // namespace semsegmap
