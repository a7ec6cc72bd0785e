#include "semsegmap/eval/scan_context_localizer.h"

namespace semsegmap {

// Measured on S1 of the simulator's world 1 (map 0:700, queries 719:722, 730:735, 805:811, from
// the best candidate's pose turned by its yaw): the candidate lies 0.3-4.2 m from the query, its
// yaw up to 6.7 degrees off. Of the seven 1.8 m or more off, the ground-truth check's
// registration brought two in and left five 1.9-4.2 m off (a voxel map reaches about one 0.5 m
// voxel); a first pass on 4 m voxels brings every query within 0.01 m. The query registers to
// the five mapped scans nearest the candidate rather than up to twenty: as exact, in about half
// the time; with two, the query 4.1 m off failed. A registration that moves the pose farther than
// its passes reach (4 + 1 m) has lost the candidate's place.
GroundTruthCheckConfig scanContextRegistration() {
  GroundTruthCheckConfig c;
  c.initial_distance_m = 4.0;
  c.max_scans = 5;
  c.max_correction_m = 5.0;
  return c;
}

ScanContextLocalizer::ScanContextLocalizer(const ScanContextLocalizerConfig& config,
                                           const Pose& T_base_lidar)
    : database_(config.scan_context), registration_(config.registration) {
  T_level_lidar_ = Pose::Identity();
  T_level_lidar_.linear() = T_base_lidar.linear();
}

void ScanContextLocalizer::addMapped(const std::vector<LidarPoint>& points,
                                     const Pose& T_world_lidar) {
  database_.add(makeScanContext(points, database_.config(), T_level_lidar_.linear()),
                T_world_lidar * T_level_lidar_.inverse());
  registration_.addMapped(points, T_world_lidar);
}

std::optional<ScanContextMatch> ScanContextLocalizer::bestMatch(
    const std::vector<LidarPoint>& points) const {
  return database_.best(makeScanContext(points, database_.config(), T_level_lidar_.linear()));
}

std::optional<ScanContextLocalization> ScanContextLocalizer::localize(
    const std::vector<LidarPoint>& points) const {
  const std::optional<ScanContextMatch> match =
      database_.query(makeScanContext(points, database_.config(), T_level_lidar_.linear()));
  if (!match) return std::nullopt;
  const std::optional<Pose> T =
      registration_.registered(points, match->T_world_query() * T_level_lidar_);
  if (!T) return std::nullopt;
  return ScanContextLocalization{*match, *T};
}

}  // namespace semsegmap
