#include "semsegmap/io/dataset_reader.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/io/csv_table.h"
#include "semsegmap/io/dataset_format.h"
#include "semsegmap/io/image_io.h"

namespace semsegmap {
namespace fs = std::filesystem;

namespace {

constexpr size_t kCsvFields = 16;
constexpr size_t kRowsPerBlock = 1024;  // one file offset kept per this many rows
// A row is about 150 bytes; a longer line is not frames.csv, and is refused before it is held.
constexpr size_t kMaxLineBytes = 64 * 1024;
// Positions beyond 10 000 km are no robot's (and float32 points there lose metres): a pose of
// 1e308 used to give 0 segments and exit 0.
constexpr double kMaxPositionM = 1e7;
// The smallest PNG: signature, IHDR and IEND chunks.
constexpr uint64_t kMinPngBytes = 8 + 25 + 12;

void requireFile(const fs::path& path) {
  if (!fs::exists(path)) throw std::runtime_error(path.string() + ": missing");
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
    for (size_t k = 0; k < 3; ++k)
      if (std::abs(v[k]) > kMaxPositionM)
        fail(columns_[first + k] + ": " + fields[first + k] + " m is beyond " +
             std::to_string(static_cast<long long>(kMaxPositionM)) + " m, no plausible position");
    if (std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]) < 1e-9)
      fail(columns_[first + 3] + ".." + columns_[first + 6] + ": quaternion has zero length");
    return fromXyzQuat(v);
  }

 private:
  std::string prefix_;
  const std::vector<std::string>& columns_;
};

// The size of a frame's file by stat, without reading it; throws "<path>: missing".
uint64_t fileSize(const fs::path& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) throw std::runtime_error(path.string() + ": missing");
    throw std::runtime_error(path.string() + ": " + std::strerror(errno));
  }
  if (!S_ISREG(st.st_mode)) throw std::runtime_error(path.string() + ": not a regular file");
  return static_cast<uint64_t>(st.st_size);
}

// A file of 4 bytes a point beside a scan of `points` points.
void expectPerPoint(const fs::path& path, const fs::path& lidar, uint64_t points) {
  const uint64_t bytes = fileSize(path);
  if (bytes != 4 * points)
    throw std::runtime_error(path.string() + ": " + std::to_string(bytes) + " bytes, expected " +
                             std::to_string(4 * points) + " (4 a point; " + lidar.string() +
                             " has " + std::to_string(points) + " points)");
}

void expectPng(const fs::path& path) {
  const uint64_t bytes = fileSize(path);
  if (bytes < kMinPngBytes)
    throw std::runtime_error(path.string() + ": " + std::to_string(bytes) +
                             " bytes is too small for a PNG");
}

Image readCameraPng(const fs::path& path, const Camera& cam, int channels) {
  requireFile(path);
  Image image = readPng(path);
  if (image.channels != channels)
    throw std::runtime_error(path.string() + ": image has " + std::to_string(image.channels) +
                             " channels, expected " + std::to_string(channels) +
                             (channels == 1 ? " (class ids)" : " (RGB)"));
  if (image.width != cam.width || image.height != cam.height)
    throw std::runtime_error(path.string() + ": image is " +
                             imageSizeText(image.width, image.height) + ", meta.yaml says " +
                             imageSizeText(cam.width, cam.height));
  return image;
}

}  // namespace

DatasetReader::DatasetReader(const fs::path& dir, size_t frames_to_check)
    : dir_(dir), csv_(dir / "frames.csv") {
  info_ = readMetaYaml(dir_ / "meta.yaml");
  // A folder's presence says that every frame has a file in it (the writer fixes the streams
  // with the first frame), which is what makes a missing file an error.
  times_dir_ = fs::is_directory(dir_ / "lidar_times");
  for (size_t k = 0; k < info_.rig.cameras.size(); ++k) {
    rgb_dirs_.push_back(fs::is_directory(dir_ / ("cam" + std::to_string(k))));
    label_dirs_.push_back(fs::is_directory(dir_ / ("cam" + std::to_string(k) + "_label")));
  }
  describeOrigin();
  requireFile(csv_);
  if (fs::is_directory(csv_)) throw std::runtime_error(csv_.string() + ": is a directory");
  file_.reset(std::fopen(csv_.c_str(), "rb"));
  if (!file_)
    throw std::runtime_error(csv_.string() + ": cannot open (" + std::strerror(errno) + ")");
  index(frames_to_check);
}

void DatasetReader::describeOrigin() {
  DatasetOrigin& o = info_.origin;
  o.kind = "dataset directory";
  o.lidar = "lidar/NNNNNN.bin";
  std::string label_dirs;
  for (size_t k = 0; k < info_.rig.cameras.size(); ++k) {
    const std::string cam = "cam" + std::to_string(k);
    o.cameras.push_back(rgb_dirs_[k] ? cam + "/NNNNNN.png" : "no pictures");
    if (label_dirs_[k]) label_dirs += (label_dirs.empty() ? "" : ", ") + cam + "_label/";
  }
  o.label_images = label_dirs;
  if (info_.has_odometry) o.odometry = "frames.csv (odom_ columns)";
  if (info_.has_ground_truth_poses) o.ground_truth = "frames.csv (gt_ columns)";
  if (info_.has_point_labels) o.point_labels = "lidar_gt/NNNNNN.bin";
}

// One pass over frames.csv: the header, then per row its field count and increasing index; the
// first `frames_to_check` rows (0: all) whole, with their files.
// Through a buffer of its own, the line ends found by memchr (a byte at a time took 13 s for
// 10^7 rows): a NUL cannot move the offsets, and an overlong line is refused before it is held.
bool DatasetReader::readLine(std::string& line, uint64_t& bytes, size_t line_number) {
  line.clear();
  bool any = false;
  while (true) {
    if (buffer_begin_ == buffer_end_) {
      buffer_.resize(1 << 20);
      buffer_begin_ = 0;
      buffer_end_ = std::fread(buffer_.data(), 1, buffer_.size(), file_.get());
      if (std::ferror(file_.get())) throw std::runtime_error(csv_.string() + ": read failed");
      if (buffer_end_ == 0) break;
    }
    any = true;
    const char* start = buffer_.data() + buffer_begin_;
    const size_t available = buffer_end_ - buffer_begin_;
    const auto* end = static_cast<const char*>(std::memchr(start, '\n', available));
    const size_t n = end ? static_cast<size_t>(end - start) : available;
    line.append(start, n);
    const size_t consumed = n + (end ? 1 : 0);
    buffer_begin_ += consumed;
    bytes += consumed;
    if (line.size() > kMaxLineBytes)
      throw std::runtime_error(csv_.string() + ": line " + std::to_string(line_number) +
                               ": longer than " + std::to_string(kMaxLineBytes) + " bytes");
    if (end) break;
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();  // files edited on Windows
  return any;
}

// Throws what is wrong with a row the index pass refused: its field count or its index.
[[noreturn]] void DatasetReader::rowError(const std::string& line, size_t line_number,
                                          bool have_previous, size_t previous) const {
  static const std::vector<std::string> columns = splitCsvFields(kFramesCsvHeader);
  const CsvRowParser p(csv_, line_number, columns);
  const size_t fields = static_cast<size_t>(std::count(line.begin(), line.end(), ',')) + 1;
  if (fields != kCsvFields)
    p.fail("expected " + std::to_string(kCsvFields) + " comma-separated fields, got " +
           std::to_string(fields));
  const size_t frame_index = p.index(line.substr(0, line.find(',')));
  if (have_previous && frame_index <= previous)
    p.fail("index " + std::to_string(frame_index) + " does not follow " + std::to_string(previous) +
           "; indices must increase");
  p.fail("malformed row");  // not reached: the index pass refuses only what is above
}

void DatasetReader::index(size_t frames_to_check) {
  uint64_t offset = 0;
  size_t line_number = 0;
  bool have_previous = false;
  size_t previous = 0;
  while (true) {
    const uint64_t start = offset;
    if (!readLine(line_, offset, line_number + 1)) break;
    ++line_number;
    if (line_number == 1) {
      if (line_ != kFramesCsvHeader)
        throw std::runtime_error(csv_.string() + ": line 1: expected the header '" +
                                 kFramesCsvHeader + "'");
      continue;
    }
    if (line_.empty()) continue;
    // The fast path takes no allocation a row; the parser only says what is wrong.
    const size_t fields = static_cast<size_t>(std::count(line_.begin(), line_.end(), ',')) + 1;
    if (fields != kCsvFields) rowError(line_, line_number, have_previous, previous);
    const size_t comma = line_.find(',');  // there is one: the row has 16 fields
    size_t frame_index = 0;
    const auto [end, ec] = std::from_chars(line_.data(), line_.data() + comma, frame_index);
    if (ec != std::errc() || end != line_.data() + comma || comma == 0 ||
        (have_previous && frame_index <= previous))
      rowError(line_, line_number, have_previous, previous);
    have_previous = true;
    previous = frame_index;
    if (rows_ % kRowsPerBlock == 0) blocks_.push_back({start, line_number});
    if (frames_to_check == 0 || rows_ < frames_to_check) checkFiles(parse(line_, line_number));
    ++rows_;
  }
  if (line_number == 0) throw std::runtime_error(csv_.string() + ": empty (no header line)");
  next_row_ = rows_;  // at the end: the next read seeks
}

DatasetReader::Row DatasetReader::parse(const std::string& line, size_t line_number) const {
  static const std::vector<std::string> columns = splitCsvFields(kFramesCsvHeader);
  const CsvRowParser p(csv_, line_number, columns);
  const std::vector<std::string> fields = splitCsvFields(line);
  if (fields.size() != kCsvFields)
    p.fail("expected " + std::to_string(kCsvFields) + " comma-separated fields, got " +
           std::to_string(fields.size()));
  Row row;
  row.index = p.index(fields[0]);
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
  return row;
}

const std::string& DatasetReader::lineOf(size_t i, size_t* line_number) {
  if (i != next_row_) {  // not the next one: from the start of its block
    const Block& b = blocks_.at(i / kRowsPerBlock);
    if (std::fseek(file_.get(), static_cast<long>(b.offset), SEEK_SET) != 0)
      throw std::runtime_error(csv_.string() + ": seek failed");
    buffer_begin_ = buffer_end_ = 0;
    next_row_ = i / kRowsPerBlock * kRowsPerBlock;
    next_line_ = b.line;
  }
  uint64_t ignored = 0;
  while (true) {
    if (!readLine(line_, ignored, next_line_))
      throw std::runtime_error(csv_.string() + ": changed while being read (ends before row " +
                               std::to_string(i) + ")");
    const size_t line = next_line_++;
    if (line_.empty()) continue;
    if (next_row_++ == i) {
      *line_number = line;
      return line_;
    }
  }
}

DatasetReader::Row DatasetReader::row(size_t i) {
  if (i >= rows_) throwFrameOutOfRange(dir_.string(), i, rows_);
  size_t line_number = 0;
  const std::string& line = lineOf(i, &line_number);
  return parse(line, line_number);
}

void DatasetReader::checkFiles(const Row& row) const {
  const fs::path lidar = dir_ / "lidar" / frameFileName(row.index, "bin");
  const uint64_t bytes = fileSize(lidar);
  if (bytes % 16 != 0)
    throw std::runtime_error(lidar.string() + ": truncated (" + std::to_string(bytes) +
                             " bytes is not a multiple of 16)");
  const fs::path bin = frameFileName(row.index, "bin");
  if (info_.has_point_labels) expectPerPoint(dir_ / "lidar_gt" / bin, lidar, bytes / 16);
  if (times_dir_) expectPerPoint(dir_ / "lidar_times" / bin, lidar, bytes / 16);
  const std::string png = frameFileName(row.index, "png");
  for (size_t k = 0; k < info_.rig.cameras.size(); ++k) {
    if (rgb_dirs_[k]) expectPng(dir_ / ("cam" + std::to_string(k)) / png);
    if (label_dirs_[k]) expectPng(dir_ / ("cam" + std::to_string(k) + "_label") / png);
  }
}

Frame DatasetReader::frame(size_t i) {
  const Row entry = row(i);
  Frame frame;
  frame.index = entry.index;
  frame.timestamp_s = entry.timestamp_s;
  frame.T_odom_base = entry.odom;
  frame.T_world_base = entry.gt;

  const fs::path lidar_path = dir_ / "lidar" / frameFileName(entry.index, "bin");
  requireFile(lidar_path);
  frame.points = readLidarBin(lidar_path);

  if (info_.has_point_labels) {
    const fs::path label_path = dir_ / "lidar_gt" / frameFileName(entry.index, "bin");
    requireFile(label_path);
    frame.point_labels = readLabelBin(label_path);
    if (frame.point_labels.size() != frame.points.size())
      throw std::runtime_error(
          label_path.string() + ": " + std::to_string(frame.point_labels.size()) + " labels, but " +
          lidar_path.string() + " has " + std::to_string(frame.points.size()) + " points");
    checkLabelClasses(label_path, frame.point_labels, info_.classes);
  }

  if (times_dir_) {
    const fs::path times_path = dir_ / "lidar_times" / frameFileName(entry.index, "bin");
    requireFile(times_path);
    frame.point_times = readPointTimesBin(times_path);
    if (frame.point_times.size() != frame.points.size())
      throw std::runtime_error(
          times_path.string() + ": " + std::to_string(frame.point_times.size()) + " times, but " +
          lidar_path.string() + " has " + std::to_string(frame.points.size()) + " points");
  }

  const std::string png = frameFileName(entry.index, "png");
  frame.cameras.resize(info_.rig.cameras.size());
  for (size_t k = 0; k < info_.rig.cameras.size(); ++k) {
    const Camera& cam = info_.rig.cameras[k];
    const fs::path rgb_dir = dir_ / ("cam" + std::to_string(k));
    const fs::path label_dir = dir_ / ("cam" + std::to_string(k) + "_label");
    if (rgb_dirs_[k]) frame.cameras[k].rgb = readCameraPng(rgb_dir / png, cam, 3);
    if (label_dirs_[k]) {
      frame.cameras[k].label = readCameraPng(label_dir / png, cam, 1);
      checkLabelClasses(label_dir / png, frame.cameras[k].label, info_.classes);
    }
  }
  return frame;
}

}  // namespace semsegmap
