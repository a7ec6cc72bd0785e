// Trajectory files in the formats the usual evaluation tools read, and the absolute trajectory
// error between an estimate and ground truth.
#pragma once

#include <cstddef>
#include <filesystem>
#include <vector>

#include "semsegmap/core/pose.h"

namespace semsegmap {

struct StampedPose {
  double timestamp_s = 0.0;
  Pose T = Pose::Identity();
};

// TUM: "timestamp x y z qx qy qz qw" per line (what evo reads), with 9 decimals (nanoseconds,
// nanometres). KITTI: the 12 numbers of the row-major 3x4 matrix per line (what the KITTI devkit
// reads); it has no timestamps. Both are written atomically (temporary file, then rename) and
// throw std::runtime_error naming the file when writing fails.
void writeTum(const std::filesystem::path& path, const std::vector<StampedPose>& poses);
void writeKitti(const std::filesystem::path& path, const std::vector<StampedPose>& poses);

// Skips blank lines and '#' comments. Throws std::runtime_error "<file>:<line>: <what is wrong>"
// for a wrong number of fields, a field that is not a finite number, or a quaternion whose norm
// is not within 1e-3 of 1 (those close to unit are normalised: files printed with few decimals).
std::vector<StampedPose> readTum(const std::filesystem::path& path);

struct TrajectoryError {
  double rmse_m = 0.0;  // translation errors, pairwise
  double mean_m = 0.0;
  double max_m = 0.0;
  double rotation_mean_deg = 0.0;
  size_t n = 0;
};

// Pairs estimate[i] with ground_truth[i] (same length, not empty, else std::invalid_argument).
// With `align`, the estimate is first moved by the rigid transform (SE3, no scale; Umeyama) that
// minimises the translation RMSE, as evo's `ape --align` does.
TrajectoryError absoluteTrajectoryError(const std::vector<Pose>& estimate,
                                        const std::vector<Pose>& ground_truth, bool align);

}  // namespace semsegmap
