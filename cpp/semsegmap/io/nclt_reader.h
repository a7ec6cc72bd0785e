// Reads an NCLT (University of Michigan North Campus) session as it is on disk (`nclt:PATH`):
// the synchronised Velodyne HDL-32E scans and, when present, the session's ground truth.
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include "semsegmap/core/frame_source.h"

namespace semsegmap {

// Layout (PATH is a session folder, e.g. 2012-01-08):
//   PATH/velodyne_sync/<utime>.bin   8 bytes per point, little-endian: uint16 x, y, z
//                                    (metres = value * 0.005 - 100), uint8 intensity, uint8 laser
//   PATH/groundtruth_*.csv           optional, at most one: utime,x,y,z,roll,pitch,yaw per line
// Frames are the scans in time order; timestamp_s = utime * 1e-6 (the file name, microseconds).
//
// Frames: velodyne_sync points are already in NCLT's body frame (the devkit projects them into
// the cameras with body-to-camera extrinsics only), so the LiDAR frame here is that body frame.
// NCLT's body and world frames are NED-like (x forward/north, y right/east, z down); the base
// and world frames of this reader are their z-up versions, a half turn about x away:
// T_base_lidar = F and T_world_base = F * T_ned_body * F with F = diag(1, -1, -1). The world
// frame is NCLT's shared one (not re-zeroed at the first frame), so sessions of different dates
// share coordinates. Ground truth is interpolated to each scan's time (linear position, slerp
// rotation); scans outside the ground truth's time span have none, and their odometry holds the
// nearest ground-truth pose (odometry = ground truth, as nothing better is read). Intensity is
// scaled to [0, 1] like KITTI's reflectance; the laser id is dropped.
//
// Known limit: no cameras. NCLT's Ladybug3 omnidirectional images need their own calibration
// files (per-camera K and extrinsics, undistortion maps) that this reader does not read.
class NcltReader : public FrameSource {
 public:
  // Lists the scans and interpolates the ground truth; throws std::runtime_error naming the
  // file and the problem (non-numeric scan name, malformed CSV line, two ground-truth files).
  explicit NcltReader(const std::filesystem::path& session_dir);

  const DatasetInfo& info() const override { return info_; }
  size_t size() const override { return frames_.size(); }
  // Decodes the scan; a file whose size is not a multiple of 8 bytes throws "<file>: truncated".
  Frame frame(size_t index) override;
  // Known from the listing: pose files pair scans by time without reading them.
  double frameTime(size_t index) override { return frames_.at(index).timestamp_s; }

 private:
  struct FrameFiles {
    std::filesystem::path scan;
    double timestamp_s = 0.0;
    Pose odom = Pose::Identity();
    std::optional<Pose> gt;
  };
  std::filesystem::path dir_;
  DatasetInfo info_;
  std::vector<FrameFiles> frames_;
};

}  // namespace semsegmap
