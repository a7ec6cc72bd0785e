// Ground removal for data without ground labels that does not rely on a fixed height: the
// ground under each point is the lowest return in its neighbourhood of the map, so a robot that
// pitches (the paper's NCLT Segway) or a road that climbs does not fool it.
#pragma once

#include <vector>

#include "semsegmap/core/enriched_point.h"
#include "semsegmap/core/pose.h"

namespace semsegmap {

struct GroundRemovalConfig {
  double cell_size_m = 1.0;      // 2-D cells of the local lowest-point grid
  int neighbourhood_cells = 1;   // the ground of a cell is the minimum over (2n+1)^2 cells
  double height_above_m = 0.25;  // points this close above the local ground are ground
};

// Marks ground points of a scan (1 = ground) given its pose in the map frame (z up). With
// `only_unobserved`, the points with a class are left 0 unasked: every point still gives its
// cell's lowest return, but only the cells of points no camera saw fit a plane, which is most of
// the work when the cameras see most of the scan.
std::vector<uint8_t> markGround(const EnrichedCloud& scan, const Pose& T_map_lidar,
                                const GroundRemovalConfig& config, bool only_unobserved = false);

}  // namespace semsegmap
