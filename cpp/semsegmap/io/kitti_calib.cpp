#include "semsegmap/io/kitti_calib.h"

#include "semsegmap/core/shown_text.h"
#include "semsegmap/io/dataset_format.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include <Eigen/LU>
#include <Eigen/SVD>

namespace semsegmap {
namespace {

std::string trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r\n");
  return std::string(s.substr(first, last - first + 1));
}

}  // namespace

std::vector<double> parseNumbers(std::string_view text) {
  std::vector<double> values;
  size_t pos = 0;
  while (pos < text.size()) {
    pos = text.find_first_not_of(" \t\r\n", pos);
    if (pos == std::string_view::npos) break;
    size_t end = text.find_first_of(" \t\r\n", pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view token = text.substr(pos, end - pos);
    // from_chars is locale-independent but does not take a leading '+'.
    std::string_view digits = token.front() == '+' ? token.substr(1) : token;
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec != std::errc() || ptr != digits.data() + digits.size() || !std::isfinite(value))
      throw std::invalid_argument("'" + shownText(token) + "' is not a finite number");
    values.push_back(value);
    pos = end;
  }
  return values;
}

void checkRotation(const Eigen::Matrix3d& R, const std::string& where) {
  const double orthogonality = (R * R.transpose() - Eigen::Matrix3d::Identity()).norm();
  const double det = R.determinant();
  if (!R.allFinite() || orthogonality > 1e-3 || std::abs(det - 1.0) > 1e-3) {
    std::ostringstream msg;
    msg << where << ": not a rotation matrix (|R R^T - I| = " << orthogonality << ", det = " << det
        << ")";
    throw std::runtime_error(msg.str());
  }
}

KittiCalibFile::KittiCalibFile(const std::filesystem::path& path) : path_(path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open calibration file");
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    if (trim(line).empty()) continue;
    const auto colon = line.find(':');
    const std::string key = colon == std::string::npos ? "" : trim(line.substr(0, colon));
    if (key.empty())
      throw std::runtime_error(path.string() + ": line " + std::to_string(line_no) +
                               ": expected 'key: values'");
    if (!entries_.emplace(key, line.substr(colon + 1)).second) throw error(key, "appears twice");
  }
}

std::runtime_error KittiCalibFile::error(const std::string& key, const std::string& problem) const {
  return std::runtime_error(path_.string() + ": " + shownText(key) + ": " +
                            shownText(problem, std::string::npos));
}

const std::string& KittiCalibFile::text(const std::string& key) const {
  const auto it = entries_.find(key);
  if (it == entries_.end()) throw error(key, "missing");
  return it->second;
}

std::vector<double> KittiCalibFile::numbers(const std::string& key, size_t count) const {
  std::vector<double> values;
  try {
    values = parseNumbers(text(key));
  } catch (const std::invalid_argument& e) {
    throw error(key, e.what());
  }
  if (values.size() != count)
    throw error(key, "expected " + std::to_string(count) + " values, found " +
                         std::to_string(values.size()));
  return values;
}

Eigen::MatrixXd KittiCalibFile::matrix(const std::string& key, int rows, int cols) const {
  const std::vector<double> v = numbers(key, static_cast<size_t>(rows) * cols);
  Eigen::MatrixXd m(rows, cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) m(r, c) = v[static_cast<size_t>(r) * cols + c];
  return m;
}

Eigen::Matrix3d KittiCalibFile::rotation(const std::string& key) const {
  const Eigen::Matrix3d R = matrix(key, 3, 3);
  checkRotation(R, path_.string() + ": " + key);
  return R;
}

Pose KittiCalibFile::transform(const std::string& rotation_key,
                               const std::string& translation_key) const {
  Pose T = Pose::Identity();
  T.linear() = rotation(rotation_key);
  T.translation() = matrix(translation_key, 3, 1);
  return T;
}

Pose KittiCalibFile::transform3x4(const std::string& key) const {
  const Eigen::MatrixXd m = matrix(key, 3, 4);
  checkRotation(m.leftCols<3>(), path_.string() + ": " + key);
  Pose T = Pose::Identity();
  T.linear() = m.leftCols<3>();
  T.translation() = m.col(3);
  return T;
}

Eigen::Matrix3d nearestRotation(const Eigen::Matrix3d& M) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  if (R.determinant() < 0) {  // a reflection is never what a pose file meant
    Eigen::Matrix3d U = svd.matrixU();
    U.col(2) *= -1.0;
    R = U * svd.matrixV().transpose();
  }
  return R;
}

std::vector<std::pair<size_t, std::filesystem::path>> listKittiFrames(
    const std::filesystem::path& dir, const std::string& extension) {
  if (!std::filesystem::is_directory(dir))
    throw std::runtime_error(dir.string() + ": missing folder");
  std::vector<std::pair<size_t, std::filesystem::path>> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (!entry.is_regular_file() || entry.path().extension() != extension) continue;
    const std::string stem = entry.path().stem().string();
    if (stem.empty() || stem.size() > 12 ||
        !std::all_of(stem.begin(), stem.end(), [](char c) { return c >= '0' && c <= '9'; }))
      throw std::runtime_error(entry.path().string() + ": expected a numeric KITTI frame name");
    files.emplace_back(static_cast<size_t>(std::stoull(stem)), entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

Camera kittiProjectionCamera(const KittiCalibFile& calib, const std::string& p_key, int width,
                             int height) {
  const Eigen::MatrixXd P = calib.matrix(p_key, 3, 4);
  // Our pinhole model has no skew and a unit third row; anything else cannot be represented
  // exactly, and an approximate camera would silently misplace colors on the points.
  const double eps = 1e-9;
  if (std::abs(P(0, 1)) > eps || std::abs(P(1, 0)) > eps || std::abs(P(2, 0)) > eps ||
      std::abs(P(2, 1)) > eps || std::abs(P(2, 2) - 1.0) > eps)
    throw std::runtime_error(calib.path().string() + ": " + p_key +
                             ": first three columns are not [fx 0 cx; 0 fy cy; 0 0 1]");
  if (!(P(0, 0) > 0 && P(1, 1) > 0))
    throw std::runtime_error(calib.path().string() + ": " + p_key +
                             ": focal lengths must be positive");
  Camera cam;
  cam.width = width;
  cam.height = height;
  cam.fx = P(0, 0);
  cam.fy = P(1, 1);
  cam.cx = P(0, 2);
  cam.cy = P(1, 2);
  // P = K [I | K^-1 p]: the fourth column is K times where the reference camera's origin lies
  // in this camera's frame (the stereo baseline), so it is a translation, not an intrinsic.
  const Eigen::Matrix3d K = P.leftCols<3>();
  cam.T_camera_lidar = Pose::Identity();
  cam.T_camera_lidar.translation() = K.inverse() * P.col(3);
  return cam;
}

Camera kittiRectifiedCamera(const KittiCalibFile& cam_to_cam, const KittiCalibFile& velo_to_cam,
                            int index) {
  const std::string suffix = "_0" + std::to_string(index);
  const std::string s_key = "S_rect" + suffix;
  const std::vector<double> size = cam_to_cam.numbers(s_key, 2);
  for (double v : size)
    if (!(v >= 1 && v < 1e5 && v == std::round(v)))
      throw std::runtime_error(cam_to_cam.path().string() + ": " + s_key +
                               ": expected a positive integer width and height");

  Camera cam = kittiProjectionCamera(cam_to_cam, "P_rect" + suffix, static_cast<int>(size[0]),
                                     static_cast<int>(size[1]));
  cam.name = "image" + suffix;
  Pose R_rect = Pose::Identity();
  R_rect.linear() = cam_to_cam.rotation("R_rect_00");
  const Pose T_cam0_velo = velo_to_cam.transform("R", "T");
  cam.T_camera_lidar = cam.T_camera_lidar * R_rect * T_cam0_velo;
  return cam;
}

double kittiScanTime(const std::vector<double>* times, const std::filesystem::path& times_path,
                     size_t number, double rate_hz) {
  if (!times) return static_cast<double>(number) / rate_hz;
  if (number >= times->size())
    throw std::runtime_error(times_path.string() + ": no line for frame " + std::to_string(number) +
                             " (" + std::to_string(times->size()) + " lines)");
  return (*times)[number];
}

Frame kittiScanFrame(size_t index, double timestamp_s, const std::filesystem::path& path) {
  Frame f;
  f.index = index;
  f.timestamp_s = timestamp_s;
  f.points = readLidarBin(path);  // rejects truncation and NaN/inf, naming the point
  return f;
}

// One line of numbers per entry; blank lines are skipped, but every other line counts so that
// line n stays frame n.
std::vector<std::vector<double>> readNumberLines(const std::filesystem::path& path,
                                                 size_t per_line) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  std::vector<std::vector<double>> rows;
  std::string line;
  for (int line_no = 1; std::getline(in, line); ++line_no) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string where = path.string() + ": line " + std::to_string(line_no);
    std::vector<double> v;
    try {
      v = parseNumbers(line);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(where + ": " + e.what());
    }
    if (v.size() != per_line)
      throw std::runtime_error(where + ": expected " + std::to_string(per_line) +
                               " values, found " + std::to_string(v.size()));
    rows.push_back(std::move(v));
  }
  return rows;
}

std::vector<Pose> readKittiPoses(const std::filesystem::path& path) {
  std::vector<Pose> poses;
  for (const auto& row : readNumberLines(path, 12)) {
    Eigen::Matrix3d R;
    R << row[0], row[1], row[2], row[4], row[5], row[6], row[8], row[9], row[10];
    checkRotation(R, path.string() + ": pose " + std::to_string(poses.size() + 1));
    Pose T = Pose::Identity();
    T.linear() = R;
    T.translation() = Eigen::Vector3d(row[3], row[7], row[11]);
    poses.push_back(T);
  }
  return poses;
}

std::vector<Pose> kittiLidarPoses(const std::vector<Pose>& camera0_poses, const Pose& Tr) {
  const Pose Tr_inv = Tr.inverse(Eigen::Affine);
  std::vector<Pose> lidar;
  lidar.reserve(camera0_poses.size());
  for (const Pose& T_world_cam : camera0_poses) {
    Pose T_world_lidar = Tr_inv * T_world_cam * Tr;
    // The files print 7 digits; a clean rotation keeps Pose::inverse() exact downstream.
    T_world_lidar.linear() = nearestRotation(T_world_lidar.linear());
    lidar.push_back(T_world_lidar);
  }
  return lidar;
}

}  // namespace semsegmap
