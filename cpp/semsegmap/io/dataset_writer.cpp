#include "semsegmap/io/dataset_writer.h"

#include <cctype>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/io/dataset_format.h"
#include "semsegmap/io/image_io.h"

namespace semsegmap {
namespace fs = std::filesystem;

namespace {

// cam<K> or cam<K>_label. Hand-rolled: std::regex trips GCC 12's -Wmaybe-uninitialized under
// the sanitizers, and this is all the pattern there is.
bool isCameraFolder(const std::string& name) {
  if (name.rfind("cam", 0) != 0) return false;
  size_t i = 3;
  while (i < name.size() && std::isdigit(static_cast<unsigned char>(name[i]))) ++i;
  if (i == 3) return false;
  return i == name.size() || name.compare(i, std::string::npos, "_label") == 0;
}

bool isFormatEntry(const std::string& name) {
  return name == "meta.yaml" || name == "frames.csv" || name == "lidar" || name == "lidar_gt" ||
         name == "lidar_times" || isCameraFolder(name);
}

// Rewriting a dataset must not leave the previous run's camK/ folders behind: the reader takes
// a folder's presence to mean that every frame has a file in it.
void prepareDirectory(const fs::path& dir) {
  if (fs::exists(dir) && !fs::is_directory(dir))
    throw std::runtime_error(dir.string() + ": exists and is not a directory");
  fs::create_directories(dir);
  const bool holds_dataset = fs::exists(dir / "meta.yaml");
  std::vector<fs::path> stale;
  for (const auto& entry : fs::directory_iterator(dir))
    if (isFormatEntry(entry.path().filename().string()) && entry.path().filename() != "meta.yaml")
      stale.push_back(entry.path());
  if (stale.empty()) return;
  if (!holds_dataset)
    throw std::runtime_error(dir.string() + ": holds " + stale.front().filename().string() +
                             " but no meta.yaml; refusing to mix a dataset into it");
  for (const auto& p : stale) fs::remove_all(p);
  // Last, so that an interruption leaves a directory that is still recognisably a dataset.
  fs::remove(dir / "meta.yaml");
}

std::string csvPose(const fs::path& csv, size_t index, const char* which, const Pose& T) {
  std::string fields;
  for (double v : toXyzQuat(T)) {
    if (!std::isfinite(v))
      throw std::invalid_argument(csv.string() + ": frame " + std::to_string(index) + ": " + which +
                                  " pose is not finite");
    fields += "," + formatExactDouble(v);
  }
  return fields;
}

fs::path cameraDir(const fs::path& dir, size_t k, bool label) {
  return dir / ("cam" + std::to_string(k) + (label ? "_label" : ""));
}

void checkImage(const fs::path& path, const Image& image, const Camera& cam, const char* kind,
                int channels) {
  if (image.channels != channels)
    throw std::invalid_argument(path.string() + ": " + kind + " image of camera '" + cam.name +
                                "' has " + std::to_string(image.channels) + " channels, expected " +
                                std::to_string(channels));
  if (image.width != cam.width || image.height != cam.height)
    throw std::invalid_argument(path.string() + ": " + kind + " image of camera '" + cam.name +
                                "' is " + imageSizeText(image.width, image.height) +
                                ", meta.yaml says " + imageSizeText(cam.width, cam.height));
  if (image.data.size() != static_cast<size_t>(image.width) * image.height * image.channels)
    throw std::invalid_argument(path.string() + ": " + kind + " image of camera '" + cam.name +
                                "' holds " + std::to_string(image.data.size()) +
                                " bytes, which does not match its size");
}

}  // namespace

DatasetWriter::DatasetWriter(const fs::path& dir, const DatasetInfo& info)
    : dir_(dir), info_(info) {
  // Validated before anything on disk changes, so a bad rig never costs the old dataset.
  try {
    info_.rig.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument((dir_ / "meta.yaml").string() + ": " + e.what());
  }
  prepareDirectory(dir_);
  writeMetaYaml(dir_ / "meta.yaml", info_);
  fs::create_directories(dir_ / "lidar");
  if (info_.has_point_labels) fs::create_directories(dir_ / "lidar_gt");
  writeFileAtomically(dir_ / "frames.csv",
                      [](std::ostream& out) { out << kFramesCsvHeader << '\n'; });
}

namespace {

[[noreturn]] void reject(const fs::path& file, const Frame& frame, const std::string& what) {
  throw std::invalid_argument(file.string() + ": frame " + std::to_string(frame.index) + ": " +
                              what);
}

}  // namespace

void DatasetWriter::checkFrame(const Frame& frame) const {
  const fs::path csv = dir_ / "frames.csv";
  if (last_index_ && frame.index <= *last_index_)
    reject(csv, frame,
           "index does not follow the previous frame's " + std::to_string(*last_index_) +
               "; indices must increase");
  if (!std::isfinite(frame.timestamp_s)) reject(csv, frame, "timestamp is not finite");
  if (frame.T_world_base && !info_.has_ground_truth_poses)
    reject(csv, frame, "has a ground-truth pose but DatasetInfo::has_ground_truth_poses is false");
  const fs::path label_path = dir_ / "lidar_gt" / frameFileName(frame.index, "bin");
  if (info_.has_point_labels) {
    if (frame.point_labels.size() != frame.points.size())
      reject(label_path, frame,
             std::to_string(frame.point_labels.size()) + " point labels for " +
                 std::to_string(frame.points.size()) + " points");
    checkLabelClasses(label_path, frame.point_labels, info_.classes);
  } else if (!frame.point_labels.empty()) {
    reject(label_path, frame, "has point labels but DatasetInfo::has_point_labels is false");
  }
  const fs::path times_path = dir_ / "lidar_times" / frameFileName(frame.index, "bin");
  if (!frame.point_times.empty() && frame.point_times.size() != frame.points.size())
    reject(times_path, frame,
           std::to_string(frame.point_times.size()) + " point times for " +
               std::to_string(frame.points.size()) + " points");
  if (last_index_ && frame.point_times.empty() == has_point_times_)
    reject(times_path, frame,
           std::string(has_point_times_ ? "lacks" : "has") +
               " per-point times, unlike the first frame written");
  const size_t n_cameras = info_.rig.cameras.size();
  if (!frame.cameras.empty() && frame.cameras.size() != n_cameras)
    reject(csv, frame,
           "has " + std::to_string(frame.cameras.size()) + " camera images but meta.yaml " +
               "lists " + std::to_string(n_cameras) + " cameras");
}

std::pair<std::vector<bool>, std::vector<bool>> DatasetWriter::checkCameras(
    const Frame& frame) const {
  const size_t n_cameras = info_.rig.cameras.size();
  const std::string png = frameFileName(frame.index, "png");
  std::vector<bool> has_rgb(n_cameras, false), has_label(n_cameras, false);
  for (size_t k = 0; k < frame.cameras.size(); ++k) {
    has_rgb[k] = !frame.cameras[k].rgb.empty();
    has_label[k] = !frame.cameras[k].label.empty();
  }
  const bool first = !last_index_.has_value();
  for (size_t k = 0; k < n_cameras; ++k) {
    const Camera& cam = info_.rig.cameras[k];
    const fs::path rgb_path = cameraDir(dir_, k, false) / png;
    const fs::path label_png = cameraDir(dir_, k, true) / png;
    if (!first && has_rgb[k] != camera_has_rgb_[k])
      reject(rgb_path, frame,
             std::string(has_rgb[k] ? "has" : "lacks") + " an rgb image of camera '" + cam.name +
                 "', unlike the first frame written");
    if (!first && has_label[k] != camera_has_label_[k])
      reject(label_png, frame,
             std::string(has_label[k] ? "has" : "lacks") + " a label image of camera '" + cam.name +
                 "', unlike the first frame written");
    if (has_rgb[k]) checkImage(rgb_path, frame.cameras[k].rgb, cam, "rgb", 3);
    if (has_label[k]) {
      checkImage(label_png, frame.cameras[k].label, cam, "label", 1);
      checkLabelClasses(label_png, frame.cameras[k].label, info_.classes);
    }
  }
  return {has_rgb, has_label};
}

void DatasetWriter::writeFiles(const Frame& frame, const std::vector<bool>& has_rgb,
                               const std::vector<bool>& has_label) {
  const size_t n_cameras = info_.rig.cameras.size();
  const std::string name = frameFileName(frame.index, "bin");
  const std::string png = frameFileName(frame.index, "png");
  if (!last_index_) {
    for (size_t k = 0; k < n_cameras; ++k) {
      if (has_rgb[k]) fs::create_directories(cameraDir(dir_, k, false));
      if (has_label[k]) fs::create_directories(cameraDir(dir_, k, true));
    }
    camera_has_rgb_ = has_rgb;
    camera_has_label_ = has_label;
    has_point_times_ = !frame.point_times.empty();
    if (has_point_times_) fs::create_directories(dir_ / "lidar_times");
  }
  writeLidarBin(dir_ / "lidar" / name, frame.points);
  if (has_point_times_) writePointTimesBin(dir_ / "lidar_times" / name, frame.point_times);
  if (info_.has_point_labels) writeLabelBin(dir_ / "lidar_gt" / name, frame.point_labels);
  for (size_t k = 0; k < n_cameras; ++k) {
    if (has_rgb[k]) writePng(cameraDir(dir_, k, false) / png, frame.cameras[k].rgb);
    if (has_label[k]) writePng(cameraDir(dir_, k, true) / png, frame.cameras[k].label);
  }
}

void DatasetWriter::write(const Frame& frame) {
  const fs::path csv = dir_ / "frames.csv";
  // Everything is checked before the first file is written, so a rejected frame leaves no trace.
  checkFrame(frame);
  const auto [has_rgb, has_label] = checkCameras(frame);
  std::string row = std::to_string(frame.index) + "," + formatExactDouble(frame.timestamp_s) +
                    csvPose(csv, frame.index, "odometry", frame.T_odom_base);
  row += frame.T_world_base ? csvPose(csv, frame.index, "ground-truth", *frame.T_world_base)
                            : std::string(",,,,,,,");
  writeFiles(frame, has_rgb, has_label);

  // The row goes last: a frame is part of the dataset only once all its files are in place.
  std::ofstream out(csv, std::ios::binary | std::ios::app);
  out << row << '\n';
  out.flush();
  if (!out)
    throw std::runtime_error(csv.string() + ": cannot append frame " + std::to_string(frame.index) +
                             " (disk full?)");
  last_index_ = frame.index;
  ++frames_written_;
}

}  // namespace semsegmap
