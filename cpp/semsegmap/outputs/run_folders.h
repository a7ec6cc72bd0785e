// Reading back what `semsegmap slam` and `semsegmap segment` write, for looking at it
// (`semsegmap view`): the folders as those commands leave them.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/graph/trajectory.h"

namespace semsegmap {

struct LoopRow {  // a line of loops.csv
  size_t frame = 0, old_frame = 0;
  int inliers = 0;
  double correction_m = 0.0;
};

// trajectory_tum.txt (loop-closed, one pose per frame), odometry_tum.txt, loops.csv; from data
// without frame times, trajectory_kitti.txt and odometry_kitti.txt instead of the TUM files.
struct SlamFolder {
  std::filesystem::path dir;
  std::vector<StampedPose> trajectory, odometry;
  std::vector<LoopRow> loops;
};

// Throws std::runtime_error "<dir>: ..." for a missing folder or file, and "<file>:<line>: ..."
// for a malformed one (a loop naming a frame beyond the trajectory among them).
SlamFolder readSlamFolder(const std::filesystem::path& dir);

struct SegmentRow {  // a line of segments.csv
  int64_t id = 0;
  size_t points = 0;
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  std::string class_name;
};

struct SegmentPoint {  // a vertex of segments.ply
  Eigen::Vector3f p = Eigen::Vector3f::Zero();
  std::array<uint8_t, 3> rgb{0, 0, 0};  // the camera's colour, black where no camera saw it
  uint16_t class_id = 0;
  int32_t segment = 0;  // SegmentRow::id
};

// segments.csv and segments.ply (the final observation of every segment).
struct SegmentFolder {
  std::filesystem::path dir;
  std::vector<SegmentRow> segments;
  std::vector<SegmentPoint> points;
};

SegmentFolder readSegmentFolder(const std::filesystem::path& dir);

// The binary PLY of artefacts/segments_io.h (x y z float, red green blue uchar, class ushort,
// segment int); throws "<path>: ..." for any other layout or a truncated file.
std::vector<SegmentPoint> readSegmentPointsPly(const std::filesystem::path& path);

}  // namespace semsegmap
