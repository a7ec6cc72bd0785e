#include "semsegmap/io/trajectory_file.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <ostream>
#include <stdexcept>
#include <string>
#include <string_view>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/io/kitti_calib.h"

namespace semsegmap {

namespace {

// to_chars/from_chars rather than printf/strtod: they ignore the C locale, which could otherwise
// turn the decimal point into a comma.
void appendNumber(std::string& line, double value, std::chars_format format, int precision) {
  char buffer[64];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value, format, precision);
  if (ec != std::errc()) throw std::runtime_error("trajectory: cannot format a number");
  if (!line.empty()) line += ' ';
  line.append(buffer, end);
}

std::vector<std::string_view> splitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

StampedPose parseTumLine(std::string_view line, const std::string& where) {
  const std::vector<std::string_view> fields = splitFields(line);
  if (fields.size() != 8)
    throw std::runtime_error(where + "expected 8 fields (timestamp x y z qx qy qz qw), got " +
                             std::to_string(fields.size()));
  double v[8];
  for (size_t i = 0; i < 8; ++i) {
    const std::string_view f = fields[i];
    const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), v[i]);
    if (ec != std::errc() || end != f.data() + f.size())
      throw std::runtime_error(where + "field " + std::to_string(i + 1) + " '" + std::string(f) +
                               "' is not a number");
    if (!std::isfinite(v[i]))
      throw std::runtime_error(where + "field " + std::to_string(i + 1) + " is not finite");
  }
  const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
  // Loose enough for files printed with ~4 decimals, tight enough to catch swapped columns.
  if (std::abs(q.norm() - 1.0) > 1e-3)
    throw std::runtime_error(where + "quaternion norm " + std::to_string(q.norm()) +
                             " is not 1 (order is qx qy qz qw)");
  StampedPose p;
  p.timestamp_s = v[0];
  p.T = Pose::Identity();
  p.T.linear() = q.normalized().toRotationMatrix();
  p.T.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
  return p;
}

}  // namespace

void writeTum(const std::filesystem::path& path, const std::vector<StampedPose>& poses) {
  writeFileAtomically(path, [&](std::ostream& out) {
    std::string line;
    for (const StampedPose& p : poses) {
      line.clear();
      appendNumber(line, p.timestamp_s, std::chars_format::fixed, 9);
      for (double v : toXyzQuat(p.T)) appendNumber(line, v, std::chars_format::fixed, 9);
      out << line << '\n';
    }
  });
}

void writeKitti(const std::filesystem::path& path, const std::vector<StampedPose>& poses) {
  writeFileAtomically(path, [&](std::ostream& out) {
    std::string line;
    for (const StampedPose& p : poses) {
      line.clear();
      const Eigen::Matrix4d m = p.T.matrix();
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) appendNumber(line, m(r, c), std::chars_format::scientific, 9);
      out << line << '\n';
    }
  });
}

std::vector<StampedPose> readTum(const std::filesystem::path& path) {
  const std::string bytes = readFileBytes(path);
  std::vector<StampedPose> poses;
  size_t line_number = 0;
  size_t start = 0;
  while (start < bytes.size()) {
    size_t end = bytes.find('\n', start);
    if (end == std::string::npos) end = bytes.size();
    std::string_view line(bytes.data() + start, end - start);
    start = end + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const size_t first = line.find_first_not_of(" \t");
    if (first == std::string_view::npos || line[first] == '#') continue;
    poses.push_back(parseTumLine(line, path.string() + ":" + std::to_string(line_number) + ": "));
  }
  return poses;
}

PoseFile readPoseFile(const std::filesystem::path& path) {
  const std::string bytes = readFileBytes(path);
  size_t start = 0;
  size_t fields = 0;
  while (start < bytes.size() && fields == 0) {
    size_t end = bytes.find('\n', start);
    if (end == std::string::npos) end = bytes.size();
    std::string_view line(bytes.data() + start, end - start);
    start = end + 1;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first != std::string_view::npos && line[first] != '#') fields = splitFields(line).size();
  }
  PoseFile file;
  if (fields == 8) {
    file.poses = readTum(path);
    if (file.poses.empty()) throw std::runtime_error(path.string() + ": no poses");
    for (size_t i = 1; i < file.poses.size(); ++i)
      if (!(file.poses[i].timestamp_s > file.poses[i - 1].timestamp_s))
        throw std::runtime_error(path.string() + ": pose " + std::to_string(i + 1) +
                                 ": the times do not increase");
    return file;
  }
  if (fields != 12)
    throw std::runtime_error(path.string() +
                             ": expected 8 numbers per line (TUM: time x y z qx "
                             "qy qz qw) or 12 (KITTI: a row-major 3x4 matrix), got " +
                             std::to_string(fields));
  file.timestamped = false;
  const std::vector<Pose> poses = readKittiPoses(path);
  for (size_t i = 0; i < poses.size(); ++i)
    file.poses.push_back({static_cast<double>(i), poses[i]});
  return file;
}

}  // namespace semsegmap
