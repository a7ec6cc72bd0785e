// One LiDAR scan from a file: PCD (ASCII, binary and binary_compressed, read by PCL), PLY (PCL)
// or KITTI's .bin (float32 x y z intensity). Any field layout is accepted (io/point_fields.h).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "semsegmap/io/point_fields.h"

namespace semsegmap {

// The extensions readPointCloudFile() reads, lower case with the dot.
bool isPointCloudFile(const std::filesystem::path& path);

// Throws std::runtime_error naming the file: missing, unreadable, truncated (fewer points than
// the header says), without x y z, or a format this build cannot read (PCD and PLY need PCL).
DecodedPoints readPointCloudFile(const std::filesystem::path& path);

}  // namespace semsegmap
