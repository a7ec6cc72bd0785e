// Poses a dataset lacks, from files: `--odometry FILE` and `--ground-truth FILE` in TUM or KITTI
// format. TUM poses are interpolated to each scan's time (which must come from the data:
// DatasetInfo::has_frame_times). KITTI poses have no times: line N is the pose of the scan
// named N (FrameSource::frameNumber); scans named otherwise take one line each in order, and only
// when the counts are equal. Which rule was used is said in one note per file.
// The files hold poses of the rig's base frame (the LiDAR when the rig does not mount it).
#pragma once

#include <filesystem>
#include <memory>

#include "semsegmap/core/frame_source.h"

namespace semsegmap {

struct PoseFileOptions {
  std::filesystem::path odometry;      // empty: the dataset's own
  std::filesystem::path ground_truth;  // empty: the dataset's own
  // KITTI odometry's calib.txt: its poses are of camera 0 and Tr turns them into LiDAR poses.
  // Empty: a calib.txt with a Tr line beside a KITTI pose file is used (said on stderr).
  std::filesystem::path kitti_calib;
  // The longest gap between two TUM poses that a scan time is interpolated across.
  double max_gap_s = 1.0;
};

// The source with its frames' T_odom_base / T_world_base replaced by the files' poses. Scans
// outside a TUM file's time span, or in a gap, are left out (counted on stderr); none left, a
// file that fits no rule above (too few KITTI poses for the largest frame number, a count that
// differs from the scans' without frame numbers, TUM poses for scans without times) or an
// unreadable file: std::runtime_error naming the file, before any frame is read.
std::unique_ptr<FrameSource> withPoseFiles(std::unique_ptr<FrameSource> source,
                                           const PoseFileOptions& options);

}  // namespace semsegmap
