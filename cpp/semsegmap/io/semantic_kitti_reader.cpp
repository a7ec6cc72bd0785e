#include "semsegmap/io/semantic_kitti_reader.h"

#include <array>
#include <cmath>
#include <fstream>
#include <stdexcept>
#include <string>

#include "semsegmap/io/dataset_format.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/io/kitti_calib.h"

namespace semsegmap {
namespace fs = std::filesystem;
const std::vector<SemanticKittiClass>& semanticKittiClasses() {
  static const std::vector<SemanticKittiClass> table = {
      {0, "unlabeled", cls::kUnknown},
      {1, "outlier", cls::kUnknown},
      {10, "car", cls::kCar},
      {11, "bicycle", cls::kCar},  // our table has one dynamic vehicle class
      {13, "bus", cls::kCar},
      {15, "motorcycle", cls::kCar},
      {16, "on-rails", cls::kCar},
      {18, "truck", cls::kCar},
      {20, "other-vehicle", cls::kCar},
      {30, "person", cls::kPerson},
      {31, "bicyclist", cls::kPerson},  // the rider; dynamic like a pedestrian
      {32, "motorcyclist", cls::kPerson},
      {40, "road", cls::kRoad},
      {44, "parking", cls::kRoad},
      {48, "sidewalk", cls::kSidewalk},
      {49, "other-ground", cls::kTerrain},  // ground that is neither road nor sidewalk
      {50, "building", cls::kBuilding},
      {51, "fence", cls::kFence},
      {52, "other-structure", cls::kOther},
      {60, "lane-marking", cls::kRoad},  // paint on the road surface
      {70, "vegetation", cls::kVegetation},
      {71, "trunk", cls::kTrunk},
      {72, "terrain", cls::kTerrain},
      {80, "pole", cls::kPole},
      {81, "traffic-sign", cls::kTrafficSign},
      {99, "other-object", cls::kOther},
      {252, "moving-car", cls::kCar},
      {253, "moving-bicyclist", cls::kPerson},
      {254, "moving-person", cls::kPerson},
      {255, "moving-motorcyclist", cls::kPerson},
      {256, "moving-on-rails", cls::kCar},
      {257, "moving-bus", cls::kCar},
      {258, "moving-truck", cls::kCar},
      {259, "moving-other-vehicle", cls::kCar},
  };
  return table;
}

namespace {

// image_2's camera: P2's pinhole after Tr, sized by the first picture (calib.txt has no size).
Camera image2Camera(const KittiCalibFile& calib, const fs::path& first_picture) {
  const Image first = readColorImage(first_picture);
  Camera cam = kittiProjectionCamera(calib, "P2", first.width, first.height);
  cam.name = "image_2";
  cam.T_camera_lidar = cam.T_camera_lidar * calib.transform3x4("Tr");
  return cam;
}

}  // namespace

ClassId semanticKittiToClass(uint16_t label) {
  // A dense lookup over the id range SemanticKITTI uses; this runs for every point.
  static const std::array<ClassId, 260> lookup = [] {
    std::array<ClassId, 260> a;
    a.fill(cls::kOther);
    for (const auto& c : semanticKittiClasses()) a[c.label] = c.class_id;
    return a;
  }();
  return label < lookup.size() ? lookup[label] : cls::kOther;
}

SemanticKittiReader::SemanticKittiReader(const fs::path& sequence_dir)
    : dir_(fs::absolute(sequence_dir).lexically_normal()) {
  if (dir_.filename().empty()) dir_ = dir_.parent_path();
  const fs::path scan_dir = dir_ / "velodyne";
  if (!fs::is_directory(scan_dir))
    throw std::runtime_error(scan_dir.string() + ": missing (not a SemanticKITTI sequence)");
  const auto scans = listKittiFrames(scan_dir, ".bin");
  if (scans.empty()) throw std::runtime_error(scan_dir.string() + ": no .bin scans");

  const fs::path label_dir = dir_ / "labels";
  const bool has_labels = fs::is_directory(label_dir);
  const fs::path times_path = dir_ / "times.txt";
  const bool has_times = fs::exists(times_path);
  std::vector<double> times;
  if (has_times)
    for (const auto& row : readNumberLines(times_path, 1)) times.push_back(row[0]);

  const fs::path poses_path = dir_ / "poses.txt";
  const bool has_poses = fs::exists(poses_path);
  std::vector<Pose> poses;
  if (has_poses) {
    // SemanticKITTI's poses are of camera 0; Tr moves them onto the Velodyne.
    const KittiCalibFile calib(dir_ / "calib.txt");
    const Pose Tr = calib.transform3x4("Tr");
    poses = kittiLidarPoses(readKittiPoses(poses_path), Tr);
  }

  const fs::path image_dir = dir_ / "image_2";
  const bool has_images = fs::is_directory(image_dir);
  for (const auto& [number, scan] : scans) {
    FrameFiles f;
    f.scan = scan;
    f.number = number;
    if (has_images) {
      f.image = image_dir / (scan.stem().string() + ".png");
      if (!fs::is_regular_file(f.image))
        throw std::runtime_error(f.image.string() + ": missing (the picture of scan " +
                                 scan.string() + ")");
    }
    if (has_labels) {
      f.labels = label_dir / (scan.stem().string() + ".label");
      if (!fs::is_regular_file(f.labels))
        throw std::runtime_error(f.labels.string() + ": missing (the labels of scan " +
                                 scan.string() + ")");
    }
    f.timestamp_s = kittiScanTime(has_times ? &times : nullptr, times_path, number,
                                  10.0);  // without times.txt, the Velodyne's 10 Hz
    if (has_poses) {
      if (number >= poses.size())
        throw std::runtime_error(poses_path.string() + ": no pose for frame " +
                                 std::to_string(number) + " (" + std::to_string(poses.size()) +
                                 " poses)");
      f.T_world_lidar = poses[number];
    }
    frames_.push_back(std::move(f));
  }

  info_.name = "semantickitti:" + dir_.filename().string();
  info_.rig.lidar = velodyneHdl64e();
  info_.rig.T_base_lidar = Pose::Identity();  // as in KITTI raw, the base is the Velodyne
  info_.rig.rate_hz = 10.0;
  if (has_images) {
    size_image_ = frames_.front().image;
    info_.rig.cameras = {image2Camera(KittiCalibFile(dir_ / "calib.txt"), size_image_)};
    try {
      info_.rig.validate();
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error((dir_ / "calib.txt").string() + ": " + e.what());
    }
  }
  info_.classes = ClassTable::Default();
  info_.origin.kind = "semantickitti";
  info_.origin.lidar = "velodyne/*.bin";
  if (has_images) info_.origin.cameras = {"image_2/*.png, calibration calib.txt (P2, Tr)"};
  if (has_poses)
    info_.origin.odometry = info_.origin.ground_truth = "poses.txt (camera 0, moved by Tr)";
  if (has_labels) info_.origin.point_labels = "labels/*.label";
  info_.has_ground_truth_poses = has_poses;
  info_.has_odometry = has_poses;  // the poses serve as odometry too
  info_.odometry_is_ground_truth = has_poses;
  info_.has_frame_times = has_times;
  info_.has_point_labels = has_labels;
}

Frame SemanticKittiReader::frame(size_t index) {
  if (index >= frames_.size()) throwFrameOutOfRange(info_.name, index, frames_.size());
  const FrameFiles& files = frames_[index];
  Frame f = kittiScanFrame(index, files.timestamp_s, files.scan);
  f.number = files.number;
  if (!files.labels.empty()) {
    f.point_labels = readLabelBin(files.labels);
    if (f.point_labels.size() != f.points.size())
      throw std::runtime_error(
          files.labels.string() + ": " + std::to_string(f.point_labels.size()) + " labels but " +
          files.scan.string() + " has " + std::to_string(f.points.size()) + " points");
    for (PointLabel& l : f.point_labels) l.class_id = semanticKittiToClass(l.class_id);
  }
  if (!files.image.empty()) {
    Image rgb = readColorImage(files.image);
    const Camera& cam = info_.rig.cameras.front();
    if (rgb.width != cam.width || rgb.height != cam.height)
      throw std::runtime_error(files.image.string() + ": picture is " +
                               imageSizeText(rgb.width, rgb.height) + " but " +
                               size_image_.string() + " is " +
                               imageSizeText(cam.width, cam.height) + " (image_2 has one size)");
    f.cameras.push_back(CameraFrame{std::move(rgb), Image(), std::nullopt});
  }
  if (files.T_world_lidar) {
    f.T_world_base = *files.T_world_lidar;
    f.T_odom_base = *files.T_world_lidar;
  }
  return f;
}

}  // namespace semsegmap
