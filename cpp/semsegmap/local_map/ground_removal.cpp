#include "semsegmap/local_map/ground_removal.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace semsegmap {

namespace {

struct Cell {
  int64_t cx = 0, cy = 0;
  Eigen::Vector3f lowest{0, 0, std::numeric_limits<float>::max()};
  bool plane_ready = false;
  Eigen::Vector3f plane{0, 0, 0};  // z = a + b x + c y, relative to `lowest`
};

uint64_t cellKey(int64_t cx, int64_t cy) {
  return (static_cast<uint64_t>(cx + (int64_t{1} << 31)) << 32) ^
         static_cast<uint64_t>(cy + (int64_t{1} << 31));
}

// The scan in the map frame on a 2-D grid: each point's cell and each cell's lowest return. Cells
// are numbered as they are met, so that each point looks its cell up once.
struct Grid {
  std::vector<Eigen::Vector3f> world;
  std::vector<uint32_t> cell_of;
  std::vector<Cell> cells;
  std::unordered_map<uint64_t, uint32_t> index;

  Grid(const EnrichedCloud& scan, const Pose& T_map_lidar, double cell_size_m) {
    const Eigen::Matrix3f R = T_map_lidar.linear().cast<float>();
    const Eigen::Vector3f t = T_map_lidar.translation().cast<float>();
    const double inv = 1.0 / cell_size_m;
    world.resize(scan.size());
    cell_of.resize(scan.size());
    index.reserve(scan.size() / 8 + 16);
    for (size_t k = 0; k < scan.size(); ++k) {
      const Eigen::Vector3f p = R * Eigen::Vector3f(scan[k].x, scan[k].y, scan[k].z) + t;
      world[k] = p;
      const auto cx = static_cast<int64_t>(std::floor(p.x() * inv));
      const auto cy = static_cast<int64_t>(std::floor(p.y() * inv));
      const auto [it, created] =
          index.try_emplace(cellKey(cx, cy), static_cast<uint32_t>(cells.size()));
      if (created) cells.push_back(Cell{cx, cy});
      cell_of[k] = it->second;
      Cell& c = cells[it->second];
      if (p.z() < c.lowest.z()) c.lowest = p;
    }
  }

  const Cell* find(int64_t cx, int64_t cy) const {
    const auto it = index.find(cellKey(cx, cy));
    return it == index.end() ? nullptr : &cells[it->second];
  }
};

// The ground of a cell is a plane fitted to the lowest returns of the cells around it: on a slope
// (or under a pitching robot) the lowest return of a window is not the ground's height everywhere
// in it, but a plane through the lowest returns is.
Eigen::Vector3f groundPlane(const Grid& grid, const Cell& self, int n) {
  std::vector<Eigen::Vector3f> lows;
  float window_min = std::numeric_limits<float>::max();
  for (int dy = -n; dy <= n; ++dy)
    for (int dx = -n; dx <= n; ++dx)
      if (const Cell* c = grid.find(self.cx + dx, self.cy + dy)) {
        lows.push_back(c->lowest);
        window_min = std::min(window_min, c->lowest.z());
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
  return coef.cast<float>();
}

}  // namespace

std::vector<uint8_t> markGround(const EnrichedCloud& scan, const Pose& T_map_lidar,
                                const GroundRemovalConfig& config, bool only_unobserved) {
  Grid grid(scan, T_map_lidar, config.cell_size_m);
  std::vector<uint8_t> ground(scan.size(), 0);
  for (size_t k = 0; k < scan.size(); ++k) {
    if (only_unobserved && scan[k].has_class) continue;
    Cell& cell = grid.cells[grid.cell_of[k]];
    if (!cell.plane_ready) {
      cell.plane = groundPlane(grid, cell, config.neighbourhood_cells);
      cell.plane_ready = true;
    }
    const Eigen::Vector3f& w = grid.world[k];
    const Eigen::Vector3f& o = cell.lowest;
    const float ground_z =
        cell.plane.x() + cell.plane.y() * (w.x() - o.x()) + cell.plane.z() * (w.y() - o.y());
    ground[k] = w.z() - ground_z < config.height_above_m;
  }
  return ground;
}

}  // namespace semsegmap
