// Reads a KITTI raw drive folder as it is on disk (`kitti-raw:PATH`): Velodyne scans, the left
// color camera image_02, the day's calibration, and oxts GPS/IMU poses when present.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "semsegmap/core/frame_source.h"

namespace semsegmap {

// Layout (PATH is the drive folder, e.g. 2011_09_26/2011_09_26_drive_0001_sync):
//   PATH/velodyne_points/data/<stem>.bin    float32 x y z reflectance
//   PATH/velodyne_points/timestamps.txt     optional; else frame <stem> is at stem * 0.1 s
//   PATH/image_02/data/<stem>.png           required for every scan, size S_rect_02
//   PATH/oxts/data/<stem>.txt               optional GPS/IMU; then calib_imu_to_velo.txt too
//   PATH/../calib_cam_to_cam.txt, PATH/../calib_velo_to_cam.txt (or two levels up)
// Frames are the scans in file-stem order. Without oxts the odometry is identity and there is
// no ground truth. No semantic labels: camera label images and point labels stay empty.
class KittiRawReader : public FrameSource {
 public:
  // Lists the files and reads the calibration; throws std::runtime_error naming the file and
  // the problem (missing calibration file or key, non-rotation, scan without image, ...).
  explicit KittiRawReader(const std::filesystem::path& drive_dir);

  const DatasetInfo& info() const override { return info_; }
  size_t size() const override { return frames_.size(); }
  // Reads the scan, the image and the oxts record of frame `index`; a truncated scan, a
  // non-finite coordinate or an image whose size differs from S_rect_02 throws naming the file.
  Frame frame(size_t index) override;
  // Known from the listing: pose files pair scans by time without reading them.
  double frameTime(size_t index) override { return frames_.at(index).timestamp_s; }
  std::optional<size_t> frameNumber(size_t index) override { return frames_.at(index).number; }

 private:
  struct FrameFiles {
    std::filesystem::path scan, image, oxts;
    double timestamp_s = 0.0;
    size_t number = 0;  // the frame number of the scan's name
  };
  Pose oxtsPose(const std::filesystem::path& oxts_file) const;

  std::filesystem::path dir_;
  std::filesystem::path cam_to_cam_path_;
  DatasetInfo info_;
  std::vector<FrameFiles> frames_;
  // oxts -> LiDAR poses: the devkit's Mercator scale of the first frame's latitude, and the
  // fixed transforms that turn an IMU pose into the LiDAR pose relative to the first frame.
  bool has_oxts_ = false;
  double mercator_scale_ = 1.0;
  Pose T_world_mercator_ = Pose::Identity();
  Pose T_imu_lidar_ = Pose::Identity();
};

}  // namespace semsegmap
