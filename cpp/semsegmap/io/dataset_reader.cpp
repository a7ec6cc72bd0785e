#include "semsegmap/io/dataset_reader.h"

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/io/dataset_format.h"
#include "semsegmap/io/image_io.h"

namespace semsegmap {
namespace fs = std::filesystem;

namespace {

constexpr size_t kCsvFields = 16;

void requireFile(const fs::path& path) {
  if (!fs::exists(path)) throw std::runtime_error(path.string() + ": missing");
}

std::vector<std::string> splitFields(const std::string& line) {
  std::vector<std::string> fields(1);
  for (char c : line) {
    if (c == ',')
      fields.emplace_back();
    else
      fields.back() += c;
  }
  return fields;
}

// Parses frames.csv rows with messages "<path>: line N: <column>: <what was wrong>".
class CsvRowParser {
 public:
  CsvRowParser(const fs::path& path, size_t line, const std::vector<std::string>& columns)
      : prefix_(path.string() + ": line " + std::to_string(line) + ": "), columns_(columns) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(prefix_ + what);
  }

  size_t index(const std::string& text) const {
    size_t value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size())
      fail("index: expected a non-negative integer, got '" + text + "'");
    return value;
  }

  // from_chars, not strtod: exact, locale-independent and it must consume the whole field.
  double number(const std::vector<std::string>& fields, size_t i) const {
    const std::string& text = fields[i];
    double value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size() ||
        !std::isfinite(value))
      fail(columns_[i] + ": expected a finite number, got '" + text + "'");
    return value;
  }

  Pose pose(const std::vector<std::string>& fields, size_t first) const {
    std::array<double, 7> v{};
    for (size_t k = 0; k < 7; ++k) v[k] = number(fields, first + k);
    if (std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]) < 1e-9)
      fail(columns_[first + 3] + ".." + columns_[first + 6] + ": quaternion has zero length");
    return fromXyzQuat(v);
  }

 private:
  std::string prefix_;
  const std::vector<std::string>& columns_;
};

std::string sizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

Image readCameraPng(const fs::path& path, const Camera& cam, int channels) {
  requireFile(path);
  Image image = readPng(path);
  if (image.channels != channels)
    throw std::runtime_error(path.string() + ": image has " + std::to_string(image.channels) +
                             " channels, expected " + std::to_string(channels) +
                             (channels == 1 ? " (class ids)" : " (RGB)"));
  if (image.width != cam.width || image.height != cam.height)
    throw std::runtime_error(path.string() + ": image is " + sizeText(image.width, image.height) +
                             ", meta.yaml says " + sizeText(cam.width, cam.height));
  return image;
}

}  // namespace

DatasetReader::DatasetReader(const fs::path& dir) : dir_(dir) {
  info_ = readMetaYaml(dir_ / "meta.yaml");

  const fs::path csv = dir_ / "frames.csv";
  requireFile(csv);
  const std::string text = readFileBytes(csv);
  const std::vector<std::string> columns = splitFields(kFramesCsvHeader);
  size_t line_number = 0;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    start = end + 1;
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();  // tolerate files edited on Windows
    if (line_number == 1) {
      if (line != kFramesCsvHeader)
        throw std::runtime_error(csv.string() + ": line 1: expected the header '" +
                                 kFramesCsvHeader + "'");
      continue;
    }
    if (line.empty()) continue;

    const CsvRowParser p(csv, line_number, columns);
    const std::vector<std::string> fields = splitFields(line);
    if (fields.size() != kCsvFields)
      p.fail("expected " + std::to_string(kCsvFields) + " comma-separated fields, got " +
             std::to_string(fields.size()));
    Row row;
    row.index = p.index(fields[0]);
    if (!rows_.empty() && row.index <= rows_.back().index)
      p.fail("index " + std::to_string(row.index) + " does not follow " +
             std::to_string(rows_.back().index) + "; indices must increase");
    row.timestamp_s = p.number(fields, 1);
    row.odom = p.pose(fields, 2);
    size_t empty_gt = 0;
    for (size_t i = 9; i < kCsvFields; ++i) empty_gt += fields[i].empty() ? 1 : 0;
    if (empty_gt == 0) {
      if (!info_.has_ground_truth_poses)
        p.fail("has a ground-truth pose but meta.yaml says has_ground_truth_poses: false");
      row.gt = p.pose(fields, 9);
    } else if (empty_gt != 7) {
      p.fail("the gt_* columns must be all filled or all empty");
    }
    rows_.push_back(row);
  }
  if (line_number == 0) throw std::runtime_error(csv.string() + ": empty (no header line)");
}

Frame DatasetReader::frame(size_t i) {
  if (i >= rows_.size()) throwFrameOutOfRange(dir_.string(), i, rows_.size());
  const Row& row = rows_[i];
  Frame frame;
  frame.index = row.index;
  frame.timestamp_s = row.timestamp_s;
  frame.T_odom_base = row.odom;
  frame.T_world_base = row.gt;

  const fs::path lidar_path = dir_ / "lidar" / frameFileName(row.index, "bin");
  requireFile(lidar_path);
  frame.points = readLidarBin(lidar_path);

  if (info_.has_point_labels) {
    const fs::path label_path = dir_ / "lidar_gt" / frameFileName(row.index, "bin");
    requireFile(label_path);
    frame.point_labels = readLabelBin(label_path);
    if (frame.point_labels.size() != frame.points.size())
      throw std::runtime_error(
          label_path.string() + ": " + std::to_string(frame.point_labels.size()) + " labels, but " +
          lidar_path.string() + " has " + std::to_string(frame.points.size()) + " points");
    checkLabelClasses(label_path, frame.point_labels, info_.classes);
  }

  // Like the camera folders: lidar_times/ present means every frame has its file.
  if (fs::is_directory(dir_ / "lidar_times")) {
    const fs::path times_path = dir_ / "lidar_times" / frameFileName(row.index, "bin");
    requireFile(times_path);
    frame.point_times = readPointTimesBin(times_path);
    if (frame.point_times.size() != frame.points.size())
      throw std::runtime_error(
          times_path.string() + ": " + std::to_string(frame.point_times.size()) + " times, but " +
          lidar_path.string() + " has " + std::to_string(frame.points.size()) + " points");
  }

  // A camera folder's presence says that every frame has an image in it (the writer fixes the
  // streams with the first frame), which is what makes a missing file an error.
  const std::string png = frameFileName(row.index, "png");
  frame.cameras.resize(info_.rig.cameras.size());
  for (size_t k = 0; k < info_.rig.cameras.size(); ++k) {
    const Camera& cam = info_.rig.cameras[k];
    const fs::path rgb_dir = dir_ / ("cam" + std::to_string(k));
    const fs::path label_dir = dir_ / ("cam" + std::to_string(k) + "_label");
    if (fs::is_directory(rgb_dir)) frame.cameras[k].rgb = readCameraPng(rgb_dir / png, cam, 3);
    if (fs::is_directory(label_dir)) {
      frame.cameras[k].label = readCameraPng(label_dir / png, cam, 1);
      checkLabelClasses(label_dir / png, frame.cameras[k].label, info_.classes);
    }
  }
  return frame;
}

}  // namespace semsegmap
