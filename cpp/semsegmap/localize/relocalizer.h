// Global relocalization from one scan: a robot that wakes up, is carried, or whose scans lie far
// apart must find itself in the map from the few partial segments one scan cuts. The frame-to-
// frame path (k nearest descriptors, a clique of at least min_inliers consistent centroids over
// the whole map) then finds too few matches: a partial segment's descriptor is far from its
// complete map segment's, so the right target is seldom among the 16 nearest, and three or four
// right matches are lost among the whole map's chance cliques.
//
// Relocalization narrows the search instead of the evidence:
//   1. place votes: every local segment's k nearest map segments vote for the map places around
//      them, each local segment once per place with its best-ranked candidate there, weighted
//      down by that rank (relocalizer.cpp);
//   2. in each of the best places only each local segment's k_in_place nearest candidates there
//      are verified, so a smaller clique (min_inliers) stands out;
//   3. a pose is accepted only when the local points register to the map's stored points
//      (localize/registration_check.h): the check that keeps a small clique from being wrong.
// When the map holds scan contexts of its scans (target_map.scan_context_apart_m), the scan's own
// scan context proposes a pose too: the mapped scan it is nearest, turned by their yaw. One
// scan's segments are few and partial on a sparse LiDAR (a VLP-32 cuts a handful), where its
// scan context, the whole scan's shape, still finds the place; the registration check decides
// alike for both.
// A prior (the last pose, a GNSS fix, a pose a user gives) restricts the places to those near it.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/localize/localizer.h"
#include "semsegmap/localize/registration_check.h"

namespace semsegmap {

// A clique of four centroids, consistent within 3 m: one scan sees parts of the map's
// segments, whose centroids lie metres from the whole segments' (a facade seen from one end), so
// the frame-to-frame tolerance (0.4 m) leaves three or four consistent matches of a dozen right
// ones, and one scan's partial segments seldom give six. The registration check, not the
// clique, keeps a relocalization from being wrong, and gives the precise pose.
inline GeometricVerificationConfig relocalizationVerification() {
  GeometricVerificationConfig c;
  c.min_inliers = 4;
  c.resolution_m = 3.0;
  c.inlier_tolerance_m = 6.0;
  return c;
}

struct RelocalizationConfig {
  // Off by default: it needs a target map with segment points (target_map.
  // max_points_per_segment). On, a frame that the local map's segments do not localize goes this
  // way when the robot has not been localized within the last `after_m` metres of driving (or
  // ever): a robot just woken up, or one whose scans lie far apart.
  bool enabled = false;
  double after_m = 10.0;
  // A localization farther than this from the pose the robot holds (its last localization
  // carried by odometry, within after_m of driving) is no correction but a jump: it must pass
  // the registration check as a lost robot's pose does, and is dropped when it does not.
  // Geometric verification alone put a simulated VLP-32 5.3 m and 15 degrees off two scans
  // after a right relocalization (world 5); 10 m of odometry drift by far less.
  double jump_m = 2.0;
  double jump_deg = 5.0;
  int k = 64;  // nearest map descriptors per local segment that vote
  // Within a place, each local segment's nearest candidates there: the place has removed the
  // look-alikes elsewhere in the map, so the right target is again among the first few.
  int k_in_place = 8;
  double place_radius_m = 60.0;  // a place: the map segments this near its centre
  double cell_m = 10.0;          // places are centred on a grid of this spacing (x, y)
  // Places verified, best voted first. Near the map's edge a place's disc holds fewer map
  // segments, so the right place gathers fewer votes than look-alikes inside the map: with 10,
  // two HDL-64E wake-ups at the edge of S1's map were found only a few frames later (ranked
  // 11th-20th at their first scan). A wrong place costs 5-20 ms of registration on a sample of
  // the scan's points before the check refuses it; the places are checked side by side.
  size_t max_places = 20;
  size_t min_votes = 4;  // a place fewer local segments voted for is not verified
  GeometricVerificationConfig verification = relocalizationVerification();
  RegistrationCheckConfig check;
  // The map's nearest scan context, when the map holds them, proposes a pose too when it is
  // nearer than this (Scan Context's own threshold, scan_context.h: at 0.2 every place it
  // accepted on S1 and on KITTI was right), of the scan contexts whose ring keys are the
  // scan_context_candidates nearest.
  bool scan_context = true;
  double scan_context_max_distance = 0.2;
  size_t scan_context_candidates = 10;
  // A pose the segments proposed and the check registered with a fitness below
  // check.min_fitness but at least this is accepted when the map's scan contexts corroborate it
  // (scanContextAgrees): two independent kinds of evidence, the segments' descriptors and the
  // whole scan's shape. A pose the scan context proposed is never corroborated by the scan
  // contexts (a proposal cannot confirm itself: on real KITTI such a pose, 0.52 on the map's
  // points, was 46.6 m wrong): it needs check.min_fitness, or at least this fitness where the
  // segments' own clique in some place proposed the same pose (within the check's
  // max_correction_m and max_correction_deg). Real scans see
  // much the map's scans did not (KITTI: right poses had 0.57 of their points on the map's,
  // wrong ones refused below 0.3), while the simulator's repeated buildings give wrong places up
  // to 0.58: the points alone cannot tell them apart, the whole scan's shape can. One VLP-32
  // scan's few segments had 0.34 and 0.42 at the right place, where Scan Context found it.
  double scan_context_min_fitness = 0.3;
  // A scan context's proposal short of check.min_fitness is also accepted when its scan
  // context distance is below this share of the nearest distance of a mapped scan 20 m or
  // more from it: no other place of the map looks nearly as alike to the whole scan (real
  // KITTI 1615: 0.08 against 0.40; its points lie 47 % on the map's).
  double scan_context_distinct_ratio = 0.5;
  // Distinctiveness: when another place, where the robot would stand farther than
  // check.max_correction_m from the best's pose, registers with at least this share of the best
  // place's fitness, the scan fits both (a straight road, a row of alike houses) and the pose is
  // ambiguous: reported, never used. Chosen on validation worlds (docs/real-data.md).
  double ambiguity_ratio = 0.9;
};

// Where the robot may be, when something else says so.
struct RelocalizationPrior {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // map frame
  double radius_m = 50.0;                              // the robot is within this of it
};

// The scan's own scan context (made with the map's grid) and the frame it was made in, in the
// local map's frame (scanContextFrame).
struct ScanContextQuery {
  ScanContext context;
  Pose T_local_scan = Pose::Identity();
};

// Whether the map's scan contexts corroborate a pose: one of the mapped scans within 10 m of where
// T_map_local puts the scan's frame is within scan_context_max_distance of the scan's, at a yaw
// within two sectors of the pose's. Mapped scans lie a metre apart, and at 5 m or more from a
// mapped scan a scan scores above the threshold anyway (scan_context.h).
bool scanContextAgrees(const TargetMap& map, const ScanContextQuery& scan, const Pose& T_map_local,
                       const RelocalizationConfig& config);

// Whether the map's scans contradict a pose's heading: mapped scans lie within 10 m of where
// T_map_local puts the scan, and at none of them does the pose's yaw agree (within two sectors)
// with the yaw that its scan context and the scan's give, however alike they are. A pose turned
// by a building's symmetry fits the points, not the whole scan: a simulated VLP-32 scan
// registered 61 % of its points 76 m off, turned 91 degrees (world 5, frame 1151), with mapped
// scans nearby whose contexts all put it at another heading; every right relocalization of the
// validation worlds' VLP-32 wake-ups near mapped scans had one that agreed. No mapped scan nearby
// (or a map without scan contexts): no contradiction.
bool headingContradicted(const TargetMap& map, const ScanContextQuery& scan,
                         const Pose& T_map_local);

// An accepted check whose heading the map's scans contradict (headingContradicted) is refused,
// when `scan` is given and config.scan_context is on.
void refuseAContradictedHeading(RegistrationCheck& check, const TargetMap& map,
                                const std::optional<ScanContextQuery>& scan,
                                const RelocalizationConfig& config);

// The registration check's verdict, widened to a fitness of scan_context_min_fitness that the
// map's scan contexts corroborate (when `scan` is given and config.scan_context is on): sets
// check.accepted and clears its reason then.
void corroborate(RegistrationCheck& check, const TargetMap& map,
                 const std::optional<ScanContextQuery>& scan, const RelocalizationConfig& config);

struct Relocalization {
  Localization match;  // T_map_local registered by the check; no matches from a scan context
  RegistrationCheck check;
  bool by_scan_context = false;  // the pose the check started from was the scan context's
  size_t places_verified = 0;
  double votes = 0;  // of the place that localized (weighted, relocalizer.cpp)
  // A scan context's proposal: its distance, and the nearest of a mapped scan elsewhere.
  double scan_context_distance = 1.0, scan_context_rival = 1.0;
  // The best fitness of a place elsewhere (config.ambiguity_ratio), 0 when none registered.
  double runner_up_fitness = 0.0;
  // The scan fits another place too: two accepted places apart, or a runner-up within
  // ambiguity_ratio of the best. The pose is the best place's, for the record; it is not a
  // localization.
  bool ambiguous = false;
};

// Whether `given` (a localization's base pose) lies farther than config.jump_m from `held` (the
// pose the robot holds), or is turned more than config.jump_deg from it: a jump, which must pass
// the registration check.
bool jumpsFrom(const Pose& held, const Pose& given, const RelocalizationConfig& config);

// `centroids`, `descriptors` and `segment_points` describe the local segments (local map frame);
// `robot_local` is the robot's position in that frame. The localizer's map must hold segment
// points. Nothing when no place passes both checks; `ambiguous` when another place far from it
// registers nearly as well (the scan fits both: no pose is safer than a wrong one). `scan`
// proposes a place too when the map holds scan contexts and config.scan_context is on.
std::optional<Relocalization> relocalize(
    const Localizer& localizer, const std::vector<Eigen::Vector3f>& centroids,
    const Eigen::MatrixXf& descriptors,
    const std::vector<std::vector<Eigen::Vector3f>>& segment_points,
    const Eigen::Vector3d& robot_local, const RelocalizationConfig& config,
    const std::optional<RelocalizationPrior>& prior = std::nullopt,
    const std::optional<ScanContextQuery>& scan = std::nullopt);

}  // namespace semsegmap
