#include "semsegmap/local_map/ground_removal.h"

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace semsegmap {

namespace {

struct CellMin {
  Eigen::Vector3f lowest{0, 0, std::numeric_limits<float>::max()};
  bool plane_ready = false;
  Eigen::Vector3f plane{0, 0, 0};  // z = a + b x + c y
};

uint64_t cellKey(int64_t cx, int64_t cy) {
  return (static_cast<uint64_t>(cx + (int64_t{1} << 31)) << 32) ^
         static_cast<uint64_t>(cy + (int64_t{1} << 31));
}

}  // namespace

std::vector<uint8_t> markGround(const EnrichedCloud& scan, const Pose& T_map_lidar,
                                const GroundRemovalConfig& config) {
  const Eigen::Matrix3f R = T_map_lidar.linear().cast<float>();
  const Eigen::Vector3f t = T_map_lidar.translation().cast<float>();
  const double inv = 1.0 / config.cell_size_m;
  auto cellOf = [&](const Eigen::Vector3f& p) {
    return std::pair<int64_t, int64_t>(static_cast<int64_t>(std::floor(p.x() * inv)),
                                       static_cast<int64_t>(std::floor(p.y() * inv)));
  };

  std::vector<Eigen::Vector3f> world(scan.size());
  std::unordered_map<uint64_t, CellMin> cells;
  cells.reserve(scan.size() / 8 + 16);
  for (size_t k = 0; k < scan.size(); ++k) {
    world[k] = R * Eigen::Vector3f(scan[k].x, scan[k].y, scan[k].z) + t;
    const auto [cx, cy] = cellOf(world[k]);
    CellMin& c = cells[cellKey(cx, cy)];
    if (world[k].z() < c.lowest.z()) c.lowest = world[k];
  }

  // The ground of a cell is a plane fitted to the lowest returns of the cells around it: on a
  // slope (or under a pitching robot) the lowest return of a window is not the ground's height
  // everywhere in it, but a plane through the lowest returns is.
  const int n = config.neighbourhood_cells;
  auto planeOf = [&](int64_t cx, int64_t cy) -> const Eigen::Vector3f& {
    CellMin& self = cells.at(cellKey(cx, cy));
    if (self.plane_ready) return self.plane;
    std::vector<Eigen::Vector3f> lows;
    float window_min = std::numeric_limits<float>::max();
    for (int dy = -n; dy <= n; ++dy)
      for (int dx = -n; dx <= n; ++dx) {
        auto it = cells.find(cellKey(cx + dx, cy + dy));
        if (it == cells.end()) continue;
        lows.push_back(it->second.lowest);
        window_min = std::min(window_min, it->second.lowest.z());
      }
    // Cells whose lowest return is far above the rest saw no ground (a wall, a car roof).
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    int used = 0;
    const Eigen::Vector3f& o = self.lowest;
    for (const auto& l : lows) {
      if (l.z() > window_min + 1.0f) continue;
      const Eigen::Vector3d row(1.0, l.x() - o.x(), l.y() - o.y());
      A += row * row.transpose();
      b += row * static_cast<double>(l.z());
      ++used;
    }
    Eigen::Vector3d coef(window_min, 0.0, 0.0);
    if (used >= 3) {
      A(1, 1) += 1e-3;  // keeps nearly collinear windows from tilting wildly
      A(2, 2) += 1e-3;
      coef = A.ldlt().solve(b);
      const double max_slope = 0.6;  // about 30 degrees: steeper is not ground
      coef(1) = std::clamp(coef(1), -max_slope, max_slope);
      coef(2) = std::clamp(coef(2), -max_slope, max_slope);
    }
    // Stored relative to the cell's lowest return.
    self.plane = Eigen::Vector3f(static_cast<float>(coef(0)), static_cast<float>(coef(1)),
                                 static_cast<float>(coef(2)));
    self.plane_ready = true;
    return self.plane;
  };

  std::vector<uint8_t> ground(scan.size(), 0);
  for (size_t k = 0; k < scan.size(); ++k) {
    const auto [cx, cy] = cellOf(world[k]);
    const Eigen::Vector3f& plane = planeOf(cx, cy);
    const Eigen::Vector3f& o = cells.at(cellKey(cx, cy)).lowest;
    const float ground_z =
        plane.x() + plane.y() * (world[k].x() - o.x()) + plane.z() * (world[k].y() - o.y());
    ground[k] = world[k].z() - ground_z < config.height_above_m;
  }
  return ground;
}

}  // namespace semsegmap
