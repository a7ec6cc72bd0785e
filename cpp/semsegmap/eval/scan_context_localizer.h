// Scan Context as a localizer of single scans, the baseline `eval revisits` shows beside the
// segment configurations: the mapped scans' scan contexts (localize/scan_context.h) give the
// mapped scan a query scan is nearest and the yaw between them; the candidate's pose turned by
// that yaw is where the query is registered from, to the mapped scans near the candidate
// (eval/ground_truth_check.h, the odometry's ICP). The registration refines the pose; it does not
// check the match: a query matched to a mapped scan 10 m along a street registers there, the
// street saying nothing along itself (S1, frames 1069-1075), so the scan context's threshold
// alone decides. It lives in eval/ because it joins the two: the scan context is a stage's, the
// registration to mapped scans the experiments'.
#pragma once

#include <optional>
#include <vector>

#include "semsegmap/core/frame.h"
#include "semsegmap/core/pose.h"
#include "semsegmap/eval/ground_truth_check.h"
#include "semsegmap/localize/scan_context.h"

namespace semsegmap {

// The registration from a match's pose, which is off by the distance between the query and the
// candidate and by up to half a sector in yaw (3 degrees: 1.6 m at 30 m): see
// scan_context_localizer.cpp.
GroundTruthCheckConfig scanContextRegistration();

struct ScanContextLocalizerConfig {
  ScanContextConfig scan_context;
  GroundTruthCheckConfig registration = scanContextRegistration();
};

struct ScanContextLocalization {
  ScanContextMatch match;
  Pose T_world_lidar = Pose::Identity();  // registered
};

class ScanContextLocalizer {
 public:
  // `T_base_lidar` levels the scans: the scan context's columns are azimuths about the base's
  // vertical, whatever the LiDAR's mounting.
  explicit ScanContextLocalizer(const ScanContextLocalizerConfig& config = {},
                                const Pose& T_base_lidar = Pose::Identity());
  // A mapped scan: its points (LiDAR frame) at its ground-truth LiDAR pose.
  void addMapped(const std::vector<LidarPoint>& points, const Pose& T_world_lidar);
  // The query's LiDAR pose: nothing when no mapped scan's scan context is near enough, or when
  // the registration from the match fails (too little overlap, or it moved the pose too far).
  std::optional<ScanContextLocalization> localize(const std::vector<LidarPoint>& points) const;
  // The nearest mapped scan by scan context, whatever its distance (for measuring the threshold).
  std::optional<ScanContextMatch> bestMatch(const std::vector<LidarPoint>& points) const;
  size_t size() const { return database_.size(); }
  // What it keeps: the scan contexts and the mapped scans' points it registers to.
  uint64_t bytes() const { return database_.bytes() + registration_.bytes(); }

 private:
  Pose T_level_lidar_;  // the LiDAR's rotation on the base: from the LiDAR to a frame with z up
  ScanContextDatabase database_;
  GroundTruthCheck registration_;
};

}  // namespace semsegmap
