#include "semsegmap/io/nclt_reader.h"

#include "semsegmap/io/kitti_calib.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>

namespace semsegmap {
namespace fs = std::filesystem;
namespace {

constexpr size_t kBytesPerPoint = 8;
constexpr double kMetresPerStep = 0.005;
constexpr double kOffsetM = -100.0;

// The half turn about x between NCLT's z-down frames and the project's z-up ones (its own
// inverse).
Pose zUpFromNed() {
  Pose F = Pose::Identity();
  F.linear() = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  return F;
}

struct GroundTruthRow {
  double utime = 0.0;  // microseconds; exact in a double up to 2^53
  Eigen::Vector3d position;
  Eigen::Quaterniond rotation;
};

double parseField(std::string_view field, const std::string& where) {
  while (!field.empty() && (field.front() == ' ' || field.front() == '\t')) field.remove_prefix(1);
  while (!field.empty() && (field.back() == ' ' || field.back() == '\t')) field.remove_suffix(1);
  double value = 0.0;
  const auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
  if (field.empty() || ec != std::errc() || ptr != field.data() + field.size())
    throw std::runtime_error(where + ": '" + std::string(field) + "' is not a number");
  return value;
}

// NCLT's groundtruth_<date>.csv: utime,x,y,z,roll,pitch,yaw (radians), no header. Rows with NaN
// (the filter's start-up) are skipped; a repeated utime keeps its first row.
std::vector<GroundTruthRow> readGroundTruth(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  std::vector<GroundTruthRow> rows;
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    if (line.back() == '\r') line.pop_back();
    const std::string where = path.string() + ": line " + std::to_string(line_no);
    double v[7];
    size_t count = 0, start = 0;
    while (start <= line.size()) {
      size_t end = line.find(',', start);
      if (end == std::string::npos) end = line.size();
      if (count < 7)
        v[count] = parseField(std::string_view(line).substr(start, end - start), where);
      ++count;
      start = end + 1;
    }
    if (count != 7)
      throw std::runtime_error(where + ": expected 7 values (utime,x,y,z,roll,pitch,yaw), found " +
                               std::to_string(count));
    if (!std::isfinite(v[0]) || v[0] != std::floor(v[0]))
      throw std::runtime_error(where + ": utime must be an integer number of microseconds");
    if (std::any_of(v + 1, v + 7, [](double x) { return std::isnan(x); })) continue;
    if (std::any_of(v + 1, v + 7, [](double x) { return !std::isfinite(x); }))
      throw std::runtime_error(where + ": infinite pose value");
    if (!rows.empty() && v[0] < rows.back().utime)
      throw std::runtime_error(where + ": utime goes back in time");
    if (!rows.empty() && v[0] == rows.back().utime) continue;
    GroundTruthRow row;
    row.utime = v[0];
    row.position = Eigen::Vector3d(v[1], v[2], v[3]);
    // The devkit's ssc_to_homo: R = Rz(yaw) Ry(pitch) Rx(roll).
    row.rotation = Eigen::AngleAxisd(v[6], Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(v[5], Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(v[4], Eigen::Vector3d::UnitX());
    rows.push_back(row);
  }
  return rows;
}

Pose toPose(const Eigen::Vector3d& p, const Eigen::Quaterniond& q) {
  Pose T = Pose::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = p;
  return T;
}

// T_ned_body at `utime`, or nothing outside the rows' time span.
std::optional<Pose> interpolate(const std::vector<GroundTruthRow>& rows, double utime) {
  if (rows.empty() || utime < rows.front().utime || utime > rows.back().utime) return std::nullopt;
  const auto hi = std::lower_bound(rows.begin(), rows.end(), utime,
                                   [](const GroundTruthRow& r, double t) { return r.utime < t; });
  if (hi->utime == utime) return toPose(hi->position, hi->rotation);
  const auto lo = hi - 1;
  const double a = (utime - lo->utime) / (hi->utime - lo->utime);
  return toPose(lo->position + a * (hi->position - lo->position),
                lo->rotation.slerp(a, hi->rotation));
}

LidarModel velodyneHdl32e() {
  LidarModel m;
  m.columns = 2250;  // about 0.16 deg azimuth step at 10 Hz
  m.rows = 32;
  m.hfov_deg = 360.0;
  m.vfov_up_deg = 10.67;
  m.vfov_down_deg = -30.67;
  m.min_range_m = 1.0;
  m.max_range_m = 100.0;
  m.range_noise_m = 0.02;
  m.dropout = 0.0;  // real scans already carry their dropouts
  return m;
}

}  // namespace

NcltReader::NcltReader(const fs::path& session_dir)
    : dir_(fs::absolute(session_dir).lexically_normal()) {
  if (dir_.filename().empty()) dir_ = dir_.parent_path();
  const fs::path scan_dir = dir_ / "velodyne_sync";
  if (!fs::is_directory(scan_dir))
    throw std::runtime_error(scan_dir.string() + ": missing (not an NCLT session folder)");

  std::vector<std::pair<int64_t, fs::path>> scans;
  for (const auto& entry : fs::directory_iterator(scan_dir)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".bin") continue;
    const std::string stem = entry.path().stem().string();
    int64_t utime = 0;
    const auto [ptr, ec] = std::from_chars(stem.data(), stem.data() + stem.size(), utime);
    if (stem.empty() || ec != std::errc() || ptr != stem.data() + stem.size() || utime < 0 ||
        utime > (int64_t(1) << 53))
      throw std::runtime_error(entry.path().string() +
                               ": file name is not a timestamp in microseconds");
    scans.emplace_back(utime, entry.path());
  }
  if (scans.empty()) throw std::runtime_error(scan_dir.string() + ": no .bin scans");
  std::sort(scans.begin(), scans.end());

  std::vector<fs::path> gt_files;
  for (const auto& entry : fs::directory_iterator(dir_)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.rfind("groundtruth_", 0) == 0 &&
        entry.path().extension() == ".csv")
      gt_files.push_back(entry.path());
  }
  if (gt_files.size() > 1)
    throw std::runtime_error(dir_.string() + ": more than one ground truth file (" +
                             gt_files[0].filename().string() + ", " +
                             gt_files[1].filename().string() + ")");
  const std::vector<GroundTruthRow> gt =
      gt_files.empty() ? std::vector<GroundTruthRow>{} : readGroundTruth(gt_files[0]);
  if (!gt_files.empty() && gt.empty())
    throw std::runtime_error(gt_files[0].string() + ": no valid ground truth row");

  const Pose F = zUpFromNed();
  for (const auto& [utime, scan] : scans) {
    FrameFiles f;
    f.scan = scan;
    f.timestamp_s = static_cast<double>(utime) * 1e-6;
    if (!gt.empty()) {
      if (const auto T_ned_body = interpolate(gt, static_cast<double>(utime))) {
        f.gt = F * *T_ned_body * F;
        f.odom = *f.gt;
      } else {
        // Hold the nearest known pose, so that odometry never jumps to the origin and back.
        const GroundTruthRow& nearest =
            static_cast<double>(utime) < gt.front().utime ? gt.front() : gt.back();
        f.odom = F * toPose(nearest.position, nearest.rotation) * F;
      }
    }
    frames_.push_back(std::move(f));
  }

  info_.name = "nclt:" + dir_.filename().string();
  info_.rig.lidar = velodyneHdl32e();
  info_.rig.T_base_lidar = F;  // LiDAR frame = NED body frame; base = its z-up version
  info_.rig.rate_hz = 10.0;
  info_.classes = ClassTable::Default();
  info_.origin.kind = "nclt";
  info_.origin.lidar = "velodyne_sync/*.bin";
  if (!gt.empty())
    info_.origin.odometry = info_.origin.ground_truth = gt_files[0].filename().string();
  info_.has_ground_truth_poses = !gt.empty();
  info_.has_odometry = !gt.empty();  // the ground truth serves as odometry too
  info_.odometry_is_ground_truth = !gt.empty();
  info_.has_point_labels = false;
}

Frame NcltReader::frame(size_t index) {
  if (index >= frames_.size()) throwFrameOutOfRange(info_.name, index, frames_.size());
  const FrameFiles& files = frames_[index];
  std::ifstream in(files.scan, std::ios::binary);
  if (!in) throw std::runtime_error(files.scan.string() + ": cannot open");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() % kBytesPerPoint != 0)
    throw std::runtime_error(files.scan.string() + ": truncated (" + std::to_string(bytes.size()) +
                             " bytes is not a whole number of 8-byte points)");

  Frame f;
  f.index = index;
  f.timestamp_s = files.timestamp_s;
  f.points.resize(bytes.size() / kBytesPerPoint);
  const auto* b = reinterpret_cast<const uint8_t*>(bytes.data());
  auto metres = [](const uint8_t* p) {
    return static_cast<float>((p[0] | (p[1] << 8)) * kMetresPerStep + kOffsetM);
  };
  for (size_t i = 0; i < f.points.size(); ++i, b += kBytesPerPoint) {
    LidarPoint& p = f.points[i];
    p.x = metres(b);
    p.y = metres(b + 2);
    p.z = metres(b + 4);
    p.intensity = static_cast<float>(b[6]) / 255.0f;
  }
  f.T_odom_base = files.odom;
  f.T_world_base = files.gt;
  return f;
}

}  // namespace semsegmap
