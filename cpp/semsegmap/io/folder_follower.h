// A folder a driver is writing into, read as it grows (`localize --follow`, for a robot without
// ROS): the folder layout of folder_reader.h (scans in the LiDAR folder, each camera's pictures
// in its folder, the rig file), and each poll hands over the files that appeared since the last.
//
// A file is taken once it has its final name: a driver writes to a hidden or .tmp/.part name and
// renames it (rename is atomic), so a half-written file is never read. A scan's time is in its
// name (1650000000.123456.pcd, or nanoseconds), as the live session needs real times to pair
// pictures and odometry; a picture's time is its name's too, or its scan's when named as one.
#pragma once

#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/io/folder_reader.h"

namespace semsegmap {

struct FollowedScan {
  double stamp_s = 0.0;
  std::filesystem::path path;
};

struct FollowedPicture {
  size_t camera = 0;
  double stamp_s = 0.0;
  std::filesystem::path path;
};

class FolderFollower {
 public:
  // Reads the rig file (as FolderReader) and checks the folders exist; no scan needs to be there
  // yet. Throws std::runtime_error naming the folder or file.
  FolderFollower(const std::filesystem::path& dir, const FolderOptions& options);
  const DatasetInfo& info() const { return info_; }

  // The files that appeared since the last call, each list in time order. A file with a name
  // that is no time throws, naming it: a live run cannot make times up.
  void poll(std::vector<FollowedScan>& scans, std::vector<FollowedPicture>& pictures);

 private:
  std::filesystem::path lidar_dir_;
  std::vector<std::filesystem::path> camera_dirs_;
  DatasetInfo info_;
  std::set<std::filesystem::path> seen_;
};

}  // namespace semsegmap
