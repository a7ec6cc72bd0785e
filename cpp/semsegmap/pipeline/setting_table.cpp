#include "semsegmap/pipeline/setting_table.h"

#include <algorithm>
#include <set>
#include <type_traits>
#include <utility>

#include "semsegmap/core/exact_text.h"
#include "semsegmap/core/sensor_rig.h"

namespace semsegmap {

namespace {

constexpr long long kMaxPoints = 100000000;  // a limit for counts of points and segments

// The key and the member it names, from one spelling: the compiler checks that every key is a
// member path of Settings.
#define SEMSEGMAP_AT(path)      \
#path, [](auto& s) -> auto& { \
    return s.path;              \
  }

enum Recorded : bool { kNotRecorded = false, kRecorded = true };

template <typename At>
using FieldOf = std::decay_t<decltype(std::declval<At>()(std::declval<Settings&>()))>;

Setting entry(const char* key, SettingKind kind, Recorded recorded, const char* description) {
  Setting s;
  s.key = key;
  s.kind = kind;
  s.recorded = recorded;
  s.description = description;
  return s;
}

// A field read and written as it is: bool, double, std::string, std::array<float, 3>.
template <typename Value, typename At>
Setting plain(SettingKind kind, const char* key, At at, Recorded recorded, const char* text) {
  static_assert(std::is_same_v<FieldOf<At>, Value>, "the field's type is not the setting's");
  Setting s = entry(key, kind, recorded, text);
  s.get = [at](const Settings& c) { return SettingValue(at(c)); };
  s.set = [at](Settings& c, const SettingValue& v) { at(c) = std::get<Value>(v); };
  return s;
}

template <typename At>
Setting flag(const char* key, At at, Recorded recorded, const char* text) {
  return plain<bool>(SettingKind::kFlag, key, at, recorded, text);
}
template <typename At>
Setting number(const char* key, At at, Recorded recorded, const char* text) {
  return plain<double>(SettingKind::kNumber, key, at, recorded, text);
}
template <typename At>
Setting text(const char* key, At at, const char* description) {
  return plain<std::string>(SettingKind::kText, key, at, kNotRecorded, description);
}
template <typename At>
Setting triple(const char* key, At at, const char* description) {
  return plain<std::array<float, 3>>(SettingKind::kTriple, key, at, kNotRecorded, description);
}

template <typename At>
Setting count(const char* key, At at, long long lo, long long hi, Recorded recorded,
              const char* text) {
  using Field = FieldOf<At>;
  static_assert(std::is_integral_v<Field> && !std::is_same_v<Field, bool>);
  Setting s = entry(key, SettingKind::kCount, recorded, text);
  s.lo = lo;
  s.hi = hi;
  s.get = [at](const Settings& c) { return SettingValue(static_cast<long long>(at(c))); };
  s.set = [at](Settings& c, const SettingValue& v) {
    at(c) = static_cast<Field>(std::get<long long>(v));
  };
  return s;
}

// An enum by its names: `names[i]` is `values[i]`.
template <typename At, typename Enum = FieldOf<At>>
Setting choice(const char* key, At at, std::vector<std::string> names, std::vector<Enum> values,
               Recorded recorded, const char* text) {
  Setting s = entry(key, SettingKind::kChoice, recorded, text);
  s.choices = names;
  s.get = [at, names, values](const Settings& c) {
    const auto it = std::find(values.begin(), values.end(), at(c));
    return SettingValue(names[static_cast<size_t>(it - values.begin())]);
  };
  s.set = [at, names, values](Settings& c, const SettingValue& v) {
    const auto it = std::find(names.begin(), names.end(), std::get<std::string>(v));
    at(c) = values[static_cast<size_t>(it - names.begin())];
  };
  return s;
}

std::vector<Setting> frontEndSettings() {
  using DR = DynamicRemoval;
  return {
      count(SEMSEGMAP_AT(enrichment.occlusion_radius_px), 0, 100, kRecorded,
            "pixels around a point's pixel in which a nearer point hides it"),
      number(SEMSEGMAP_AT(enrichment.occlusion_tolerance_m), kRecorded,
             "how much nearer a point must be to hide another (metres)"),
      number(SEMSEGMAP_AT(enrichment.occlusion_tolerance_rel), kRecorded,
             "and as a share of the depth"),
      number(SEMSEGMAP_AT(local_map.voxel_size_m), kRecorded, "the local map's voxel edge"),
      number(SEMSEGMAP_AT(local_map.radius_m), kRecorded, "the local map's cylinder radius"),
      count(SEMSEGMAP_AT(local_map.min_points_per_voxel), 1, 1000000, kRecorded,
            "points a voxel needs to become active"),
      flag(SEMSEGMAP_AT(local_map.remove_dynamic_classes), kRecorded,
           "drop points of dynamic classes (person, car)"),
      choice(SEMSEGMAP_AT(local_map.dynamic_removal), {"point", "voxel"}, {DR::kPoint, DR::kVoxel},
             kRecorded, "dynamic points dropped one by one, or by their voxel's class votes"),
      number(SEMSEGMAP_AT(local_map.dynamic_vote_share), kRecorded,
             "by voxel: the dynamic share of its votes above which a voxel is dropped"),
      flag(SEMSEGMAP_AT(local_map.remove_ground_classes), kRecorded,
           "drop points of ground classes (road, sidewalk, terrain)"),
      flag(SEMSEGMAP_AT(local_map.remove_unknown_class), kRecorded,
           "drop points the network called unknown"),
      flag(SEMSEGMAP_AT(local_map.remove_unobserved), kRecorded,
           "drop points no camera saw (when others of the scan have a class)"),
      flag(SEMSEGMAP_AT(local_map.geometric_ground_removal), kRecorded,
           "remove the ground geometrically from every point, also those with a class"),
      number(SEMSEGMAP_AT(local_map.ground.cell_size_m), kRecorded,
             "cells of the geometric ground's lowest-point grid"),
      count(SEMSEGMAP_AT(local_map.ground.neighbourhood_cells), 0, 100, kRecorded,
            "a cell's ground is the lowest point over (2n+1)^2 cells"),
      number(SEMSEGMAP_AT(local_map.ground.height_above_m), kRecorded,
             "points this close above the ground are ground"),
      number(SEMSEGMAP_AT(segmentation.d_segment_m), kRecorded,
             "voxels nearer than this (semantic distance) grow one segment"),
      number(SEMSEGMAP_AT(segmentation.hue_threshold), kRecorded,
             "hue difference above which the hue penalty applies (hue in [0, 1))"),
      number(SEMSEGMAP_AT(segmentation.hue_penalty), kRecorded, "distance added for other hues"),
      number(SEMSEGMAP_AT(segmentation.class_penalty), kRecorded,
             "distance added for other classes"),
      count(SEMSEGMAP_AT(segmentation.min_segment_points), 0, kMaxPoints, kRecorded,
            "smaller segments are not reported"),
      count(SEMSEGMAP_AT(segmentation.max_segment_points), 0, kMaxPoints, kRecorded,
            "larger segments are dropped for good"),
      number(SEMSEGMAP_AT(segmentation.observation_growth), kRecorded,
             "a segment grown by this share of its points is observed again"),
      flag(SEMSEGMAP_AT(segmentation.keep_all_observation_points), kNotRecorded,
           "keep every observation's points, not only the latest (training data)"),
      text(SEMSEGMAP_AT(descriptor.kind), "semsegmap-net, segmap-cnn, 3dsmoothnet, eigen or fpfh"),
      text(SEMSEGMAP_AT(descriptor.model),
           "model file of a learned descriptor, relative to the config file"),
      text(SEMSEGMAP_AT(descriptor.model_lidar_only),
           "the model taken instead for input with neither colour nor classes"),
      count(SEMSEGMAP_AT(descriptor.batch), 1, 4096, kNotRecorded,
            "segments described per forward pass"),
      // Not recorded: the describer's fingerprint, which the map keeps, says it instead.
      count(SEMSEGMAP_AT(descriptor.keypoints), 0, 1024, kNotRecorded,
            "3dsmoothnet: keypoints a segment is described at, 0: the model's"),
  };
}

std::vector<Setting> localizationSettings() {
  return {
      count(SEMSEGMAP_AT(localization.localizer.index.k), 1, 1000, kNotRecorded,
            "nearest target descriptors per local segment"),
      count(SEMSEGMAP_AT(localization.localizer.index.exact_below), 0, kMaxPoints, kNotRecorded,
            "maps with fewer descriptors are searched exactly"),
      count(SEMSEGMAP_AT(localization.localizer.index.ivf_lists), 0, kMaxPoints, kNotRecorded,
            "inverted lists of a larger map's index (0: 4 sqrt(n))"),
      count(SEMSEGMAP_AT(localization.localizer.index.ivf_probes), 1, 100000, kNotRecorded,
            "inverted lists scanned per query"),
      count(SEMSEGMAP_AT(localization.localizer.index.ivf_training_iterations), 1, 1000,
            kNotRecorded, "k-means iterations of the inverted lists"),
      number(SEMSEGMAP_AT(localization.localizer.verification.resolution_m), kNotRecorded,
             "consistent correspondences' centroid distances differ by at most this"),
      count(SEMSEGMAP_AT(localization.localizer.verification.min_inliers), 3, 10000, kNotRecorded,
            "correspondences a localization needs"),
      flag(SEMSEGMAP_AT(localization.localizer.verification.refine), kNotRecorded,
           "refit the transform on the final inliers"),
      number(SEMSEGMAP_AT(localization.localizer.verification.inlier_tolerance_m), kNotRecorded,
             "an inlier lies within this of its target under the fitted transform"),
      number(SEMSEGMAP_AT(localization.localizer.verification.min_spread_m), kNotRecorded,
             "inliers spread less than this across their main axis are refused"),
      count(SEMSEGMAP_AT(localization.localizer.verification.max_search_nodes), 1, 1000000000,
            kNotRecorded, "branch-and-bound nodes before the search settles"),
      count(SEMSEGMAP_AT(localization.localizer.min_local_segments), 0, 1000000, kNotRecorded,
            "fewer described local segments: no query"),
      count(SEMSEGMAP_AT(localization.every_n_frames), 1, 1000000, kNotRecorded,
            "query the target map every n-th frame"),
      number(SEMSEGMAP_AT(localization.latest_scan_fallback_m), kNotRecorded,
             "a scan this far from the one before is also tried alone (0: off)"),
      flag(SEMSEGMAP_AT(localization.refinement.enabled), kNotRecorded,
           "refine a match's pose by registering segment points"),
      count(SEMSEGMAP_AT(localization.refinement.max_points_per_segment), 1, 1000000, kNotRecorded,
            "points a local segment contributes"),
      number(SEMSEGMAP_AT(localization.refinement.coarse_distance_m), kNotRecorded,
             "correspondence distance of the coarse pass"),
      number(SEMSEGMAP_AT(localization.refinement.fine_distance_m), kNotRecorded,
             "correspondence distance of the fine pass"),
      number(SEMSEGMAP_AT(localization.refinement.kernel_scale_m), kNotRecorded,
             "Geman-McClure scale"),
      number(SEMSEGMAP_AT(localization.refinement.max_correction_m), kNotRecorded,
             "a refinement moving the pose further keeps the match's pose"),
      count(SEMSEGMAP_AT(localization.refinement.min_correspondences), 0, kMaxPoints, kNotRecorded,
            "fewer correspondences keep the match's pose"),
      number(SEMSEGMAP_AT(localization.refinement.neighbours_m), kNotRecorded,
             "also register unmatched segments this near a map segment (0: matched only)"),
  };
}

// Relocalization (localize/relocalizer.h) and its registration check.
std::vector<Setting> relocalizationSettings() {
  return {
      flag(SEMSEGMAP_AT(localization.relocalization.enabled), kNotRecorded,
           "search the whole map when the robot has not been localized for a while"),
      number(SEMSEGMAP_AT(localization.relocalization.after_m), kNotRecorded,
             "metres driven without a localization before relocalizing"),
      number(SEMSEGMAP_AT(localization.relocalization.jump_m), kNotRecorded,
             "a localization this far from the held pose must pass the registration check"),
      number(SEMSEGMAP_AT(localization.relocalization.jump_deg), kNotRecorded,
             "or turned this much from it"),
      count(SEMSEGMAP_AT(localization.relocalization.k), 1, 4096, kNotRecorded,
            "nearest map descriptors per local segment that vote for places"),
      count(SEMSEGMAP_AT(localization.relocalization.k_in_place), 1, 4096, kNotRecorded,
            "of those, each local segment's nearest in a place that are verified"),
      number(SEMSEGMAP_AT(localization.relocalization.place_radius_m), kNotRecorded,
             "a place: the map segments this near its centre"),
      number(SEMSEGMAP_AT(localization.relocalization.cell_m), kNotRecorded,
             "spacing of the places' centres"),
      count(SEMSEGMAP_AT(localization.relocalization.max_places), 1, 1000, kNotRecorded,
            "places verified, best voted first"),
      count(SEMSEGMAP_AT(localization.relocalization.min_votes), 1, 100000, kNotRecorded,
            "local segments that must vote for a place to verify it"),
      number(SEMSEGMAP_AT(localization.relocalization.verification.resolution_m), kNotRecorded,
             "pairwise consistency tolerance within a place"),
      count(SEMSEGMAP_AT(localization.relocalization.verification.min_inliers), 3, 1000,
            kNotRecorded, "consistent correspondences a place needs"),
      flag(SEMSEGMAP_AT(localization.relocalization.verification.refine), kNotRecorded,
           "refit the transform on the final inliers"),
      number(SEMSEGMAP_AT(localization.relocalization.verification.inlier_tolerance_m),
             kNotRecorded, "an inlier lies within this of its target"),
      number(SEMSEGMAP_AT(localization.relocalization.verification.min_spread_m), kNotRecorded,
             "inliers spread less than this across their main axis are refused"),
      count(SEMSEGMAP_AT(localization.relocalization.verification.max_search_nodes), 1, 1000000000,
            kNotRecorded, "branch-and-bound nodes before the search settles"),
      count(SEMSEGMAP_AT(localization.relocalization.check.max_points_per_segment), 1, 1000000,
            kNotRecorded, "local points a segment contributes to the check"),
      number(SEMSEGMAP_AT(localization.relocalization.check.coarse_distance_m), kNotRecorded,
             "correspondence distance of the check's coarse pass"),
      number(SEMSEGMAP_AT(localization.relocalization.check.retry_coarse_distance_m), kNotRecorded,
             "a coarse pass leaving the points off the map's is retried this near (0: never)"),
      number(SEMSEGMAP_AT(localization.relocalization.check.fine_distance_m), kNotRecorded,
             "correspondence distance of the check's fine pass"),
      number(SEMSEGMAP_AT(localization.relocalization.check.kernel_scale_m), kNotRecorded,
             "Geman-McClure scale of the check's registration"),
      number(SEMSEGMAP_AT(localization.relocalization.check.near_m), kNotRecorded,
             "a local point with a map point this near is an inlier"),
      number(SEMSEGMAP_AT(localization.relocalization.check.min_fitness), kNotRecorded,
             "share of local points that must lie on the map's"),
      count(SEMSEGMAP_AT(localization.relocalization.check.min_points), 1, kMaxPoints, kNotRecorded,
            "fewer local or map points: refused"),
      number(SEMSEGMAP_AT(localization.relocalization.check.max_correction_m), kNotRecorded,
             "registration may move the proposed pose this far"),
      number(SEMSEGMAP_AT(localization.relocalization.check.max_correction_deg), kNotRecorded,
             "and turn it this much"),
      number(SEMSEGMAP_AT(localization.relocalization.check.max_tilt_deg), kNotRecorded,
             "the registered pose may tilt the local map this much against the map"),
      number(SEMSEGMAP_AT(localization.relocalization.check.place_radius_m), kNotRecorded,
             "map points this near the robot are registered to"),
      flag(SEMSEGMAP_AT(localization.relocalization.scan_context), kNotRecorded,
           "the map's nearest scan context proposes a place too (maps that hold them)"),
      number(SEMSEGMAP_AT(localization.relocalization.scan_context_max_distance), kNotRecorded,
             "a scan context this near or farther proposes nothing"),
      count(SEMSEGMAP_AT(localization.relocalization.scan_context_candidates), 1, 100000,
            kNotRecorded, "mapped scans with the nearest ring keys compared in full"),
      number(SEMSEGMAP_AT(localization.relocalization.scan_context_min_fitness), kNotRecorded,
             "a lower fitness the map's scan contexts near the pose corroborate"),
      number(SEMSEGMAP_AT(localization.relocalization.scan_context_distinct_ratio), kNotRecorded,
             "a scan context's proposal short of the fitness, this much nearer than elsewhere"),
      number(SEMSEGMAP_AT(localization.relocalization.ambiguity_ratio), kNotRecorded,
             "a place elsewhere registering this share of the best's fitness: ambiguous"),
      number(SEMSEGMAP_AT(localization.covariance.registration_inflation), kNotRecorded,
             "multiplies the covariance of a registration's point-to-plane evidence"),
      number(SEMSEGMAP_AT(localization.covariance.centroid_inflation), kNotRecorded,
             "multiplies the covariance of the matched centroids' evidence"),
      number(SEMSEGMAP_AT(localization.covariance.min_sigma_m), kNotRecorded,
             "floor under every position sigma"),
      number(SEMSEGMAP_AT(localization.covariance.min_sigma_deg), kNotRecorded,
             "floor under every rotation sigma"),
      number(SEMSEGMAP_AT(localization.covariance.max_sigma_m), kNotRecorded,
             "cap: the position sigma of a direction nothing constrains"),
      number(SEMSEGMAP_AT(localization.covariance.max_sigma_deg), kNotRecorded,
             "cap: the rotation sigma of a direction nothing constrains"),
      number(SEMSEGMAP_AT(localization.covariance.degeneracy_ratio), kNotRecorded,
             "a direction with less information per correspondence is unconstrained"),
  };
}

std::vector<Setting> mapAndLoopSettings() {
  return {
      number(SEMSEGMAP_AT(target_map.duplicate_distance_m), kNotRecorded,
             "a segment this near one added earlier replaces it (0: off)"),
      // The map file stores a segment's point count in 16 bits (artefacts/map_file.cpp).
      count(SEMSEGMAP_AT(target_map.max_points_per_segment), 0, 65535, kNotRecorded,
            "points kept per map segment (pictures, pose refinement)"),
      number(SEMSEGMAP_AT(target_map.earlier_observations_apart_m), kNotRecorded,
             "keep earlier observations this far apart (0: the final one alone)"),
      number(SEMSEGMAP_AT(target_map.scan_context_apart_m), kNotRecorded,
             "with segment points, keep a scan context this often (0: none)"),
      number(SEMSEGMAP_AT(loop_closure.exclude_recent_m), kNotRecorded,
             "segments finished within this much driving are no loop candidates"),
      number(SEMSEGMAP_AT(loop_closure.min_travel_between_loops_m), kNotRecorded,
             "driving between two loop edges"),
      number(SEMSEGMAP_AT(loop_closure.graph.odometry_translation_sigma_m), kNotRecorded,
             "odometry edges' translation sigma"),
      number(SEMSEGMAP_AT(loop_closure.graph.odometry_rotation_sigma_rad), kNotRecorded,
             "odometry edges' rotation sigma"),
      number(SEMSEGMAP_AT(loop_closure.graph.loop_translation_sigma_m), kNotRecorded,
             "loop edges' translation sigma"),
      number(SEMSEGMAP_AT(loop_closure.graph.loop_rotation_sigma_rad), kNotRecorded,
             "loop edges' rotation sigma"),
      number(SEMSEGMAP_AT(loop_closure.graph.loop_robust_scale), kNotRecorded,
             "Cauchy loss scale of loop edges in sigmas (<= 0: none)"),
      count(SEMSEGMAP_AT(loop_closure.graph.max_iterations), 1, 100000, kNotRecorded,
            "the pose graph solver's iterations"),
      count(SEMSEGMAP_AT(loop_closure.graph.threads), 1, 1024, kNotRecorded,
            "the pose graph solver's threads"),
      number(SEMSEGMAP_AT(session_merge.same_segment_m), kNotRecorded,
             "a merged session's segment this near an older one of its class is that segment"),
      count(SEMSEGMAP_AT(session_merge.min_localizations), 1, 1000000, kNotRecorded,
            "localizations a session needs to join a map"),
  };
}

std::vector<Setting> odometrySettings() {
  return {
      number(SEMSEGMAP_AT(odometry.voxel_size_m), kNotRecorded, "the odometry map's voxel edge"),
      number(SEMSEGMAP_AT(odometry.max_range_m), kNotRecorded, "farther points are dropped"),
      number(SEMSEGMAP_AT(odometry.min_range_m), kNotRecorded, "nearer points are dropped"),
      count(SEMSEGMAP_AT(odometry.max_points_per_voxel), 1, 10000, kNotRecorded,
            "points kept per odometry voxel"),
      number(SEMSEGMAP_AT(odometry.initial_threshold_m), kNotRecorded,
             "correspondence threshold before the motion adapts it"),
      number(SEMSEGMAP_AT(odometry.min_motion_m), kNotRecorded,
             "motion a frame must show to adapt the threshold"),
      number(SEMSEGMAP_AT(odometry.min_threshold_m), kNotRecorded,
             "the correspondence threshold never drops below this"),
      flag(SEMSEGMAP_AT(odometry.deskew), kNotRecorded, "deskew scans with per-point times"),
      count(SEMSEGMAP_AT(odometry.min_points), 0, kMaxPoints, kNotRecorded,
            "fewer registration points: the prediction is used"),
      choice(SEMSEGMAP_AT(odometry.icp.metric), {"point_to_plane", "point_to_point"},
             {IcpMetric::kPointToPlane, IcpMetric::kPointToPoint}, kNotRecorded,
             "the ICP's residual"),
      count(SEMSEGMAP_AT(odometry.icp.max_iterations), 1, 10000, kNotRecorded, "ICP iterations"),
      number(SEMSEGMAP_AT(odometry.icp.convergence), kNotRecorded,
             "stop when an update moves the pose by less than this"),
      number(SEMSEGMAP_AT(odometry.icp.degeneracy_ratio), kNotRecorded,
             "directions constrained less than this are left alone"),
      count(SEMSEGMAP_AT(odometry.icp.min_correspondences), 0, kMaxPoints, kNotRecorded,
            "fewer correspondences: the prediction is used"),
  };
}

// channel_order is the network's, bgr what the code keeps of it.
Setting channelOrder() {
  Setting s = entry("semantics.channel_order", SettingKind::kChoice, kNotRecorded,
                    "the network's channel order (semantics.bgr in the code)");
  s.choices = {"rgb", "bgr"};
  s.get = [](const Settings& c) {
    return SettingValue(std::string(c.semantics.bgr ? "bgr" : "rgb"));
  };
  s.set = [](Settings& c, const SettingValue& v) {
    c.semantics.bgr = std::get<std::string>(v) == "bgr";
  };
  return s;
}

std::vector<Setting> semanticsSettings() {
  using RP = ResizePolicy;
  using NO = NetworkOutput;
  return {
      text(SEMSEGMAP_AT(semantics.model), "ONNX file relative to the config file (empty: none)"),
      text(SEMSEGMAP_AT(semantics.class_map), "a shipped class map's name or a YAML file"),
      count(SEMSEGMAP_AT(semantics.input_width), 0, kMaxCameraSide, kNotRecorded,
            "the network's input width (0: the picture's)"),
      count(SEMSEGMAP_AT(semantics.input_height), 0, kMaxCameraSide, kNotRecorded,
            "the network's input height (0: the picture's)"),
      choice(SEMSEGMAP_AT(semantics.resize), {"stretch", "letterbox", "crop"},
             {RP::kStretch, RP::kLetterbox, RP::kCenterCrop}, kNotRecorded,
             "how a picture is fitted to the input"),
      triple(SEMSEGMAP_AT(semantics.mean), "per-channel mean of [0, 1] pixels, R G B"),
      triple(SEMSEGMAP_AT(semantics.std), "per-channel standard deviation, R G B"),
      channelOrder(),
      choice(SEMSEGMAP_AT(semantics.output), {"logits", "argmax"}, {NO::kLogits, NO::kArgmax},
             kNotRecorded, "the network's output: scores or class ids"),
      count(SEMSEGMAP_AT(semantics.threads), 0, 1024, kNotRecorded,
            "OpenCV threads while the network runs"),
      number(SEMSEGMAP_AT(semantics.rate_hz), kNotRecorded,
             "at most this many pictures a second per camera (0: every frame)"),
      number(SEMSEGMAP_AT(semantics.budget_cores), kNotRecorded,
             "the network's share of the cores on average (0: no limit)"),
      number(SEMSEGMAP_AT(semantics.tolerance_s), kNotRecorded,
             "a scan takes labels at most this much older"),
      number(SEMSEGMAP_AT(semantics.latency_s), kNotRecorded,
             "the network's time per picture when a recording replays the budget"),
      flag(SEMSEGMAP_AT(semantics.replace_dataset_labels), kNotRecorded,
           "run the network on pictures that have labels too"),
  };
}

#undef SEMSEGMAP_AT

std::vector<Setting> allSettings() {
  std::vector<Setting> all;
  for (auto part : {frontEndSettings, localizationSettings, relocalizationSettings,
                    mapAndLoopSettings, odometrySettings, semanticsSettings}) {
    std::vector<Setting> settings = part();
    std::move(settings.begin(), settings.end(), std::back_inserter(all));
  }
  return all;
}

std::vector<SettingAlias> allAliases() {
  std::vector<SettingAlias> aliases = {
      {"localization.k", "localization.localizer.index.k"},
      {"localization.exact_below", "localization.localizer.index.exact_below"},
      {"localization.resolution_m", "localization.localizer.verification.resolution_m"},
      {"localization.min_inliers", "localization.localizer.verification.min_inliers"},
      {"localization.min_local_segments", "localization.localizer.min_local_segments"},
      {"local_map.ground_cell_size_m", "local_map.ground.cell_size_m"},
      {"local_map.ground_neighbourhood_cells", "local_map.ground.neighbourhood_cells"},
      {"local_map.ground_height_above_m", "local_map.ground.height_above_m"},
  };
  // The refinement section was a section of its own; loop closure's sigmas and the odometry's
  // ICP settings sat in their sections beside the rest.
  for (const char* name :
       {"enabled", "max_points_per_segment", "coarse_distance_m", "fine_distance_m",
        "kernel_scale_m", "max_correction_m", "min_correspondences", "neighbours_m"})
    aliases.push_back(
        {std::string("refinement.") + name, std::string("localization.refinement.") + name});
  for (const char* name : {"odometry_translation_sigma_m", "odometry_rotation_sigma_rad",
                           "loop_translation_sigma_m", "loop_rotation_sigma_rad"})
    aliases.push_back(
        {std::string("loop_closure.") + name, std::string("loop_closure.graph.") + name});
  for (const char* name :
       {"metric", "max_iterations", "convergence", "degeneracy_ratio", "min_correspondences"})
    aliases.push_back({std::string("odometry.") + name, std::string("odometry.icp.") + name});
  return aliases;
}

bool startsWith(const std::string& text, const std::string& prefix) {
  return text.size() > prefix.size() && text.compare(0, prefix.size(), prefix) == 0;
}

}  // namespace

const std::vector<Setting>& settingTable() {
  static const std::vector<Setting> table = allSettings();
  return table;
}

const Setting* findSetting(const std::string& key) {
  for (const Setting& s : settingTable())
    if (s.key == key) return &s;
  return nullptr;
}

const std::vector<SettingAlias>& settingAliases() {
  static const std::vector<SettingAlias> aliases = allAliases();
  return aliases;
}

std::string currentSettingKey(const std::string& key) {
  for (const SettingAlias& a : settingAliases())
    if (a.old_key == key) return a.key;
  return key;
}

bool isSettingGroup(const std::string& path) {
  const std::string prefix = path + ".";
  for (const Setting& s : settingTable())
    if (startsWith(s.key, prefix)) return true;
  for (const SettingAlias& a : settingAliases())
    if (startsWith(a.old_key, prefix)) return true;
  return false;
}

std::vector<std::string> settingNamesBelow(const std::string& path) {
  const std::string prefix = path.empty() ? "" : path + ".";
  std::set<std::string> names;
  auto add = [&](const std::string& key) {
    if (!prefix.empty() && !startsWith(key, prefix)) return;
    const std::string rest = key.substr(prefix.size());
    names.insert(rest.substr(0, rest.find('.')));
  };
  for (const Setting& s : settingTable()) add(s.key);
  for (const SettingAlias& a : settingAliases()) add(a.old_key);
  return {names.begin(), names.end()};
}

std::string settingText(const SettingValue& value) {
  struct Text {
    std::string operator()(bool v) const { return v ? "true" : "false"; }
    std::string operator()(long long v) const { return std::to_string(v); }
    std::string operator()(double v) const { return formatExactDouble(v); }
    std::string operator()(const std::string& v) const { return v; }
    std::string operator()(const std::array<float, 3>& v) const {
      return "[" + formatExactDouble(v[0]) + ", " + formatExactDouble(v[1]) + ", " +
             formatExactDouble(v[2]) + "]";
    }
  };
  return std::visit(Text{}, value);
}

}  // namespace semsegmap
