// Reads a SemanticKITTI (or KITTI odometry) sequence folder as it is on disk
// (`semantickitti:PATH`): Velodyne scans with per-point labels, the left colour camera image_2
// when the folder has it, and the sequence's poses.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "semsegmap/core/frame_source.h"

namespace semsegmap {

// One row of the SemanticKITTI -> ClassTable::Default() mapping.
struct SemanticKittiClass {
  uint16_t label = 0;     // SemanticKITTI's raw label id (semantic-kitti.yaml)
  const char* name = "";  // its SemanticKITTI name
  ClassId class_id = cls::kOther;
};

// The mapping, one row per SemanticKITTI id; ids not listed map to cls::kOther. Choices worth
// knowing: parking and lane-marking -> road; other-ground -> terrain (so it stays ground);
// every vehicle, moving or not, two-wheelers included -> car (dynamic); riders -> person;
// unlabeled and outlier -> unknown.
const std::vector<SemanticKittiClass>& semanticKittiClasses();
ClassId semanticKittiToClass(uint16_t label);

// Layout (PATH is a sequence folder, e.g. dataset/sequences/08):
//   PATH/velodyne/<NNNNNN>.bin     float32 x y z reflectance
//   PATH/labels/<NNNNNN>.label     optional folder; uint32 per point: class low 16, instance
//                                  high 16
//   PATH/image_2/<NNNNNN>.png      optional folder; then a picture for every scan, all of one
//                                  size (the first one's)
//   PATH/poses.txt                 optional; 3x4 row-major camera-0 poses, line n for frame n
//   PATH/calib.txt                 P0..P3 and Tr (velodyne -> rectified camera 0); needed with
//                                  poses.txt or image_2 (then P2 and Tr)
//   PATH/times.txt                 optional; seconds per frame, else frame n is at n * 0.1 s
// Poses become LiDAR poses T_world_velo = Tr^-1 * T_world_cam0 * Tr (identity at frame 0);
// odometry is the same pose, as nothing better ships with the sequence. With image_2 the rig has
// one camera "image_2": P2's intrinsics, T_camera_lidar = Translation(K^-1 P2[:,3]) * Tr (as the
// devkit projects, P2 * Tr * X); frames carry its picture and no label image, so a label set or
// a network gives the camera's classes. Without image_2: no cameras.
class SemanticKittiReader : public FrameSource {
 public:
  // Lists the files and reads poses, times and calibration; throws std::runtime_error naming
  // the file and the problem (missing label file for a scan, too few poses, bad Tr, ...).
  explicit SemanticKittiReader(const std::filesystem::path& sequence_dir);

  const DatasetInfo& info() const override { return info_; }
  size_t size() const override { return frames_.size(); }
  // Reads the scan, its labels and its picture; a picture of another size than the first, a
  // label count that differs from the point count, a truncated
  // file or a non-finite coordinate throws naming the file(s).
  Frame frame(size_t index) override;
  // Known from the listing: pose files pair scans by time without reading them.
  double frameTime(size_t index) override { return frames_.at(index).timestamp_s; }
  std::optional<size_t> frameNumber(size_t index) override { return frames_.at(index).number; }

 private:
  struct FrameFiles {
    std::filesystem::path scan, labels;  // labels empty when the sequence has none
    std::filesystem::path image;         // empty when the sequence has no image_2
    double timestamp_s = 0.0;
    size_t number = 0;  // the frame number of the scan's name
    std::optional<Pose> T_world_lidar;
  };
  std::filesystem::path dir_;
  DatasetInfo info_;
  std::vector<FrameFiles> frames_;
  std::filesystem::path size_image_;  // the picture the camera's size was read from
};

}  // namespace semsegmap
