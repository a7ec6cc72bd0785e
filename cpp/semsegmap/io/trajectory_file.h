// Trajectory files in the formats the usual evaluation tools read.
#pragma once

#include <filesystem>
#include <vector>

#include "semsegmap/core/stamped_pose.h"

namespace semsegmap {

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

// A pose file in either format, told apart by the number of fields on its first pose line
// (8: TUM, 12: KITTI). KITTI files have no times: their poses are stamped with their line
// index (0, 1, ...), and pair with frames by index.
struct PoseFile {
  bool timestamped = true;  // TUM
  std::vector<StampedPose> poses;
};
PoseFile readPoseFile(const std::filesystem::path& path);

}  // namespace semsegmap
