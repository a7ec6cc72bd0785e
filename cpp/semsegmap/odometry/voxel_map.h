// The local map of the odometry: points kept per voxel in a hash table (no tree to rebuild per
// scan), cropped to a radius around the robot, with the plane of each voxel for point-to-plane
// registration. Also the voxel downsampling of a scan.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace semsegmap {

// One point per voxel of edge `voxel_size_m` (the first that falls in it, so the result does not
// drift towards dense regions the way a mean would).
std::vector<Eigen::Vector3d> voxelDownsample(const std::vector<Eigen::Vector3d>& points,
                                             double voxel_size_m);

// An open-addressing table from a packed voxel key to an index: a map lookup per query point and
// iteration is the hot loop of registration, and std::unordered_map's buckets cost a cache miss
// more per lookup.
class VoxelIndex {
 public:
  static constexpr uint32_t kNone = UINT32_MAX;
  void clear(size_t expected);
  uint32_t find(uint64_t key) const;
  // The index stored for key, inserting `value` first when the key is new.
  uint32_t findOrInsert(uint64_t key, uint32_t value);
  size_t size() const { return size_; }

 private:
  void grow();
  std::vector<uint64_t> keys_;
  std::vector<uint32_t> values_;
  size_t size_ = 0;
  uint64_t mask_ = 0;
};

uint64_t voxelKeyOf(const Eigen::Vector3d& p, double inverse_voxel_size);

// The closest map point to a query and the plane of its voxel.
struct MapNeighbour {
  bool found = false;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit; zero when the voxel is not planar
  bool linear = false;  // the voxel's points lie along a line: no plane, no reliable point
  double distance_sq = 0.0;
};

class VoxelMap {
 public:
  VoxelMap(double voxel_size_m = 1.0, int max_points_per_voxel = 20);

  // Points in the odometry frame; a full voxel takes no more (the map keeps its first views,
  // which are the ones the registered poses were estimated against). The planes of the voxels
  // are fitted to `plane_points` (all points of the scan, not the downsampled ones: a voxel
  // holds too few of those for a plane); a voxel they reach only gets a plane, no point.
  void add(const std::vector<Eigen::Vector3d>& points,
           const std::vector<Eigen::Vector3d>& plane_points);
  // Drops the voxels whose first point is farther than max_distance_m from `center`.
  void removeFarFrom(const Eigen::Vector3d& center, double max_distance_m);
  // The closest point within max_distance_m among the 3 x 3 x 3 voxels around `query` (every
  // point within a voxel is among them), or with `near_only` among the 2 x 2 x 2 nearest (every
  // point within half a voxel: enough once registration has nearly converged); or
  // found = false.
  MapNeighbour closest(const Eigen::Vector3d& query, double max_distance_m,
                       bool near_only = false) const;

  bool empty() const { return voxels_.empty(); }
  size_t voxelCount() const { return voxels_.size(); }
  size_t pointCount() const;
  std::vector<Eigen::Vector3d> points() const;
  double voxelSize() const { return voxel_size_; }

 private:
  struct Voxel {
    uint64_t key = 0;
    Eigen::Vector3d corner = Eigen::Vector3d::Zero();  // the moments are taken about it
    std::vector<Eigen::Vector3f> points;
    // First and second moments of the plane points, for the plane fit.
    double count = 0.0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d sum_sq = Eigen::Matrix3d::Zero();
    Eigen::Vector3f normal = Eigen::Vector3f::Zero();
    bool linear = false;  // its points lie along a line
    bool dirty = false;   // moments changed since the normal was fitted
  };
  Voxel& voxelAt(const Eigen::Vector3d& p);
  void fitNormal(Voxel& voxel) const;
  void rebuildIndex();

  double voxel_size_, inverse_voxel_size_;
  size_t max_points_;
  std::vector<Voxel> voxels_;
  VoxelIndex index_;
};

}  // namespace semsegmap
