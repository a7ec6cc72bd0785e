// The local map (paper section III-B): a voxel grid inside a cylinder of radius R around the
// robot that moves with it. Points fuse into voxels (running centroid and colour, class votes);
// dynamic and ground classes are filtered out; a voxel becomes active at a minimum point count,
// and each update reports the voxels that became active and those that left the cylinder.
#pragma once

#include <string>
#include <unordered_map>
#include <vector>

#include "semsegmap/core/class_table.h"
#include "semsegmap/core/enriched_point.h"
#include "semsegmap/core/pose.h"
#include "semsegmap/local_map/ground_removal.h"
#include "semsegmap/local_map/voxel.h"

namespace semsegmap {

// How points of dynamic classes (the class table's dynamic flag: car, person) leave the map.
enum class DynamicRemoval {
  kPoint,  // each such point is dropped: the mislabelled edges of a moving truck survive
  kVoxel,  // a voxel is dropped when its class votes say dynamic by majority
};
DynamicRemoval parseDynamicRemoval(const std::string& name);  // point | voxel
std::string dynamicRemovalName(DynamicRemoval removal);       // its inverse

struct LocalMapConfig {
  double voxel_size_m = 0.1;
  double radius_m = 50.0;
  uint32_t min_points_per_voxel = 1;
  bool remove_dynamic_classes = true;  // person, car: the class table's dynamic flag
  // A real network labels the edges of a car as the wall behind it and the other way round; by
  // voxel, a voxel whose points are more than dynamic_vote_share dynamic is never made active
  // (its static minority goes with it), and the dynamic minority of a static voxel counts in
  // its geometry and colour but not its class.
  DynamicRemoval dynamic_removal = DynamicRemoval::kVoxel;
  double dynamic_vote_share = 0.5;
  bool remove_ground_classes = true;  // road, sidewalk, terrain: the ground flag
  // Points the network called unknown (or ignore): what it could not name is mostly clutter.
  // Unobserved points (no class at all, EnrichedPoint::has_class) are not of this class.
  bool remove_unknown_class = true;
  // Unobserved points of a scan in which other points have a class: the paper's rig, whose
  // cameras cover its LiDAR, drops them, since what no camera saw cannot be filtered by class.
  // Off, they are kept with their geometry alone (a front camera on a 360-degree LiDAR sees a
  // quarter of the scan); their ground is then removed geometrically, and their class comes
  // from the votes of the frames in which a camera sees their voxel.
  bool remove_unobserved = false;
  // Geometric ground removal of every point, also those with a class, for labels whose ground is
  // not trusted. Unobserved points always have their ground removed geometrically (all points
  // of a scan without any semantics).
  bool geometric_ground_removal = false;
  GroundRemovalConfig ground;
};

struct LocalMapUpdate {
  std::vector<VoxelKey> newly_active;
  std::vector<VoxelKey> removed;  // left the cylinder (only voxels that were active)
  size_t points_inserted = 0;
  size_t points_filtered = 0;
  size_t points_unobserved = 0;  // of the scan, before filtering: no class (has_class false)
};

class LocalMap {
 public:
  LocalMap(const LocalMapConfig& config, const ClassTable& classes);

  // Fuses one enriched scan (LiDAR frame) taken at T_map_lidar, then moves the cylinder to the
  // robot's position `robot_xy` and drops what left it. Points with a class are filtered by it
  // (ground, dynamic, unknown); unobserved points (has_class false) have no class to filter by:
  // their ground is removed geometrically and they vote for no class. A moving object that no
  // camera saw therefore stays, unless its voxels collect dynamic votes before they become
  // active. A scan without any class (LiDAR only) is thus all geometry.
  LocalMapUpdate update(const EnrichedCloud& scan, const Pose& T_map_lidar,
                        const Eigen::Vector2d& robot_xy);

  const Voxel* find(VoxelKey key) const;
  Eigen::Vector3i voxelIndex(const Eigen::Vector3f& p) const;
  size_t size() const { return voxels_.size(); }
  size_t activeCount() const { return active_count_; }
  const LocalMapConfig& config() const { return config_; }
  const std::unordered_map<VoxelKey, Voxel>& voxels() const { return voxels_; }

 private:
  void dropOutside(const Eigen::Vector2f& center, LocalMapUpdate& out);
  uint64_t tileOf(const Eigen::Vector3i& voxel_index) const;

  LocalMapConfig config_;
  int tile_voxels_ = 20;
  std::vector<uint8_t> drop_class_;     // by class id: dropped point by point, per the config
  std::vector<uint8_t> dynamic_class_;  // by class id: voted on by voxel, per the config
  uint32_t scan_ = 0;                   // updates so far: marks the voxels pending this one
  std::unordered_map<VoxelKey, Voxel> voxels_;
  // Voxels grouped by 2-D tile: moving the cylinder tests whole tiles and only looks at single
  // voxels in the tiles its rim crosses, instead of sweeping every voxel every frame.
  std::unordered_map<uint64_t, std::vector<VoxelKey>> tiles_;
  size_t active_count_ = 0;
  bool dropped(const EnrichedPoint& q, bool ground, bool drop_unobserved) const;

  std::vector<uint8_t> ground_mask_;  // scratch, reused every update
};

}  // namespace semsegmap
