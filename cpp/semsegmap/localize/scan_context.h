// Scan Context (Kim and Kim, "Scan Context: Egocentric Spatial Descriptor for Place Recognition
// within 3D Point Cloud Map", IROS 2018): a whole scan as one descriptor, the baseline the
// segment-based localization is compared with (`eval revisits`). The scan is cut into a polar grid
// around the sensor (rings by range, sectors by azimuth) and each bin keeps the greatest height of
// its points. Two scan contexts are compared column by column (a column is a sector: every ring
// at one azimuth) after shifting one by whole sectors, so the comparison finds the yaw between
// the two scans as well; the ring key (each ring's occupancy) does not change with yaw and picks
// the few mapped scans worth comparing.
//
// Yaw convention: the scans are taken in a frame whose z axis points up (the LiDAR levelled by the
// rig). A query whose sensor is turned by `yaw` counterclockwise about z from the candidate's,
// T_candidate_query = Rz(yaw), sees the candidate's column j in its column j - yaw / sector; the
// comparison reports that yaw, so T_world_query = T_world_candidate * Rz(yaw).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/frame.h"
#include "semsegmap/core/pose.h"

namespace semsegmap {

struct ScanContextConfig {
  size_t rings = 20;           // radial bins out to max_radius_m (the paper's N_r)
  size_t sectors = 60;         // azimuthal bins, 6 degrees each (N_s): the yaw's resolution
  double max_radius_m = 80.0;  // points farther are left out (L_max)
  // Added to every height (the sensor's frame has z = 0 at the sensor): an empty bin reads 0, so a
  // bin of ground, about one LiDAR height below the sensor (1.73 m on KITTI's HDL-64E, 1.9 m on
  // the simulator's rig), must read above 0 to count as occupied, and the cosine similarity of
  // two columns then compares heights above the ground, all of one sign. The paper's LiDAR
  // height, rounded up; a point lower still (a slope down) occupies its bin with a small height.
  double height_offset_m = 2.0;
  size_t candidates = 10;  // mapped scans with the nearest ring keys compared in full
  // A match is accepted when its distance (1 - mean cosine similarity of the column pairs) is
  // below this. Measured with the other defaults, each query's best candidate: on KITTI 00's
  // sparse scans (map 0:23, queries 24:35 of eval revisits) the three queries within 1.5 m of a
  // mapped scan score 0.08-0.11 to it, the nine elsewhere 0.29-0.37 to a wrong one; on S1 of the
  // simulator's world 1 (map 0:700, queries 701:1416, the paper's 270-degree rig) candidates
  // within 2 m of the query score 0.03-0.30 (143 of 155 below 0.2), and those farther than 5 m
  // from 0.22 up (0.223 and 0.245 for frames 1071 and 1069, 10 m along the street the query
  // drives 3 m beside). At 0.2 every match accepted on both was the right place (3 and 143, all
  // registered within 1 m); at 0.25 S1 accepts two 10 m off, at 0.3 nine, and KITTI two.
  double max_distance = 0.2;
};

// A scan's descriptor: rings x sectors bins, each the height of the highest point in it plus the
// height offset (0: no point), and the ring key, each ring's share of occupied sectors.
struct ScanContext {
  Eigen::MatrixXf bins;  // row = ring (nearest first), column = sector (counterclockwise from +x)
  Eigen::VectorXf ring_key;
  size_t occupied = 0;  // bins with a point
  bool empty() const { return occupied == 0; }
};

// The scan context of `points` (sensor frame), levelled by `R_level_sensor` (the rotation from the
// sensor to a frame with z up, e.g. the rig's T_base_lidar rotation). Points that are not finite,
// or farther than max_radius_m (horizontally), are left out; a scan with none left gives an empty
// scan context.
ScanContext makeScanContext(const std::vector<LidarPoint>& points, const ScanContextConfig& config,
                            const Eigen::Matrix3d& R_level_sensor = Eigen::Matrix3d::Identity());
// The frame a LiDAR's scan context is made in: the LiDAR's position on the base, turned as the
// base is (z up), whatever the LiDAR's own mounting.
Pose scanContextFrame(const Pose& T_world_base, const Pose& T_base_lidar);

// A scan context of stored bins (a map file's): the ring key and occupancy follow from them.
ScanContext scanContextOfBins(Eigen::MatrixXf bins);

struct ScanContextDistance {
  double distance = 1.0;  // 1 - mean cosine similarity of the non-empty column pairs; 1: none
  size_t shift = 0;       // sectors: the query's column j is paired with the candidate's j + shift
  double yaw_rad = 0.0;   // the shift as a yaw in (-pi, pi]: T_candidate_query = Rz(yaw_rad)
};

// The smallest distance over all column shifts, and that shift. Throws std::invalid_argument when
// the two have different grids; an empty one gives distance 1 (nothing in common).
ScanContextDistance scanContextDistance(const ScanContext& query, const ScanContext& candidate);

struct ScanContextMatch {
  size_t index = 0;  // of the mapped scan, in the order added
  ScanContextDistance distance;
  Pose T_world_candidate = Pose::Identity();
  // The query's pose from the match alone: the candidate's turned by the yaw (no translation).
  Pose T_world_query() const;
};

// The mapped scans and their poses. The ring keys are searched by brute force: a few thousand
// scans of 20 floats each take microseconds, far below one scan context comparison's cost; a map
// of millions of scans would put them into a DescriptorIndex (descriptor_index.h).
class ScanContextDatabase {
 public:
  // Not explicit without arguments: a map (TargetMap) holds one, and value-initializing a struct
  // that holds a map ({}) copy-initializes it.
  ScanContextDatabase() : ScanContextDatabase(ScanContextConfig{}) {}
  explicit ScanContextDatabase(const ScanContextConfig& config);
  struct MappedScan {
    ScanContext context;
    Pose T_world_scan;  // the levelled frame the scan context was made in
  };
  // Returns the scan's index. An empty scan context is kept (indices follow the caller's scans)
  // but never matches.
  size_t add(ScanContext context, const Pose& T_world_scan);
  size_t size() const { return scans_.size(); }
  const std::vector<MappedScan>& scans() const { return scans_; }
  uint64_t bytes() const;  // of the scan contexts and ring keys
  const ScanContextConfig& config() const { return config_; }
  // Of the `candidates` mapped scans whose ring keys are nearest the query's, the one whose scan
  // context is nearest, whatever its distance; nothing when the database or the query is empty.
  std::optional<ScanContextMatch> best(const ScanContext& query) const;
  // best(), when its distance is below config().max_distance.
  std::optional<ScanContextMatch> query(const ScanContext& query) const;
  // Of the `candidates` mapped scans whose ring keys are nearest the query's, the `n` nearest by
  // scan context, nearest first, whatever their distance.
  std::vector<ScanContextMatch> nearest(const ScanContext& query, size_t candidates,
                                        size_t n) const;

 private:
  ScanContextConfig config_;
  std::vector<MappedScan> scans_;
};

}  // namespace semsegmap
