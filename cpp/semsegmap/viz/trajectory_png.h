// Bird's-eye picture of trajectories (ground truth, odometry, loop-closed) with the loop
// closures as lines between the two places they connect.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/pose.h"

namespace semsegmap::viz {

struct TrajectoryCurve {
  std::string name;
  uint8_t r = 255, g = 255, b = 255;
  std::vector<Pose> poses;
};

void writeTrajectoriesPng(const std::filesystem::path& png, const std::string& title,
                          const std::vector<TrajectoryCurve>& curves,
                          const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& links);

}  // namespace semsegmap::viz
