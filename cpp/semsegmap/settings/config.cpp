#include "semsegmap/settings/config.h"

#include "semsegmap/core/diagnostics.h"
#include "semsegmap/core/sensor_rig.h"
#include "semsegmap/core/shown_text.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

namespace semsegmap {

namespace {

// A section is a table of key -> setter; anything not in the table is an error, so a typo in a
// config never silently leaves a default in place.
using Setter = std::function<void(const YAML::Node&)>;

constexpr long long kMaxPoints = 100000000;  // a limit for counts of points and segments

// A value of the wrong type or out of range: readSection adds the file and the key.
struct BadValue {
  std::string what;
};

std::string shown(const YAML::Node& n) {
  if (n.IsScalar()) return "'" + shownText(n.Scalar()) + "'";
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a mapping";
  return "nothing";
}

template <typename T>
const char* expected() {
  if constexpr (std::is_same_v<T, bool>) return "true or false";
  if constexpr (std::is_same_v<T, std::string>) return "a string";
  if constexpr (std::is_floating_point_v<T>) return "a finite number";
  return "a list of finite numbers";
}

template <typename T>
bool finite(const T& value) {
  if constexpr (std::is_floating_point_v<T>) return std::isfinite(value);
  if constexpr (std::is_same_v<T, std::vector<float>>)
    return std::all_of(value.begin(), value.end(), [](float v) { return std::isfinite(v); });
  return true;
}

template <typename T>
T decode(const YAML::Node& n) {
  T value{};
  bool ok = n.IsScalar() || std::is_same_v<T, std::vector<float>>;
  try {
    ok = ok && YAML::convert<T>::decode(n, value) && finite(value);
  } catch (const YAML::Exception&) {  // an element of a list that is no number
    ok = false;
  }
  if (!ok) throw BadValue{std::string("expected ") + expected<T>() + ", got " + shown(n)};
  return value;
}

// Counts go through count() with their limits, so that no count read from a file can make the
// program allocate what it says (localization.k: 1000000000 was std::bad_alloc).
template <typename T>
Setter set(T& field) {
  static_assert(!std::is_integral_v<T> || std::is_same_v<T, bool>, "counts are read by count()");
  return [&field](const YAML::Node& n) { field = decode<T>(n); };
}

template <typename T>
Setter count(T& field, long long lo, long long hi) {
  return [&field, lo, hi](const YAML::Node& n) {
    long long value = 0;
    bool ok = n.IsScalar();
    try {
      ok = ok && YAML::convert<long long>::decode(n, value);
    } catch (const YAML::Exception&) {
      ok = false;
    }
    if (!ok || value < lo || value > hi)
      throw BadValue{"expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                     "], got " + shown(n)};
    field = static_cast<T>(value);
  };
}

std::string keyOf(const std::filesystem::path& path, const YAML::Node& key,
                  const std::string& where) {
  if (!key.IsScalar())
    throw std::runtime_error(path.string() + ": " + where + ": a key that is " + shown(key));
  return shownText(key.Scalar(), std::string::npos);  // a key is shown in messages as it is
}

void readSection(const std::filesystem::path& path, const YAML::Node& root, const std::string& name,
                 const std::map<std::string, Setter>& keys) {
  const YAML::Node section = root[name];
  if (!section) return;
  if (!section.IsMap())
    throw std::runtime_error(path.string() + ": " + name + ": expected a mapping");
  for (const auto& kv : section) {
    const std::string key = keyOf(path, kv.first, name);
    auto it = keys.find(key);
    if (it == keys.end())
      throw std::runtime_error(path.string() + ": " + name + "." + key + ": unknown key");
    try {
      it->second(kv.second);
    } catch (const BadValue& e) {
      throw std::runtime_error(path.string() + ": " + name + "." + key + ": wrong type: " + e.what);
    }
  }
}

}  // namespace

namespace {

// The YAML document, whose top level may hold only the known sections.
YAML::Node loadConfigRoot(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::exists(path, error))
    throw std::runtime_error(path.string() + ": no such config file");
  if (!std::filesystem::is_regular_file(path, error))
    throw std::runtime_error(path.string() + ": not a config file (a directory or a device)");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path.string() + ": not valid YAML (" + shownText(e.msg) + ")");
  } catch (const std::exception& e) {  // the stream's own errors
    throw std::runtime_error(path.string() + ": cannot read (" + shownText(e.what()) + ")");
  }
  if (!root.IsMap())
    throw std::runtime_error(path.string() + ": expected a mapping at the top level");
  const std::map<std::string, bool> sections = {
      {"enrichment", true},   {"local_map", true},  {"segmentation", true}, {"descriptor", true},
      {"localization", true}, {"target_map", true}, {"loop_closure", true}, {"odometry", true},
      {"semantics", true},    {"refinement", true}};
  for (const auto& kv : root) {
    const std::string key = keyOf(path, kv.first, "the top level");
    if (!sections.count(key))
      throw std::runtime_error(path.string() + ": " + key + ": unknown section");
  }

  return root;
}

void checkPipelineConfig(const std::filesystem::path& path, const PipelineConfig& c) {
  const auto& lm = c.local_map;
  const auto& sg = c.segmentation;
  const auto& d = c.descriptor;
  const auto& loc = c.localization;
  const auto& lc = c.loop_closure;
  auto check = [&](bool ok, const std::string& what) {
    if (!ok) throw std::runtime_error(path.string() + ": " + what);
  };
  check(lm.voxel_size_m > 0, "local_map.voxel_size_m: must be positive");
  check(lm.radius_m > lm.voxel_size_m, "local_map.radius_m: must exceed the voxel size");
  check(lm.min_points_per_voxel >= 1, "local_map.min_points_per_voxel: must be at least 1");
  check(lm.dynamic_vote_share >= 0 && lm.dynamic_vote_share < 1,
        "local_map.dynamic_vote_share: must be in [0, 1)");
  check(sg.d_segment_m > 0, "segmentation.d_segment_m: must be positive");
  check(sg.hue_threshold >= 0 && sg.hue_threshold <= 0.5,
        "segmentation.hue_threshold: must be in [0, 0.5]");
  check(sg.hue_penalty >= 0 && sg.class_penalty >= 0,
        "segmentation: penalties must not be negative");
  check(sg.min_segment_points <= sg.max_segment_points,
        "segmentation.min_segment_points: must not exceed max_segment_points");
  check(c.enrichment.occlusion_radius_px >= 0,
        "enrichment.occlusion_radius_px: must not be negative");
  check(d.batch >= 1, "descriptor.batch: must be at least 1");
  check(d.model_lidar_only.empty() || !d.model.empty(),
        "descriptor.model_lidar_only: only for a learned descriptor (one with a model)");
  check(loc.localizer.index.k >= 1, "localization.k: must be at least 1");
  check(loc.localizer.verification.resolution_m > 0, "localization.resolution_m: must be positive");
  check(loc.localizer.verification.min_inliers >= 3,
        "localization.min_inliers: must be at least 3 (a rigid transform needs 3 points)");
  check(loc.every_n_frames >= 1, "localization.every_n_frames: must be at least 1");
  check(c.target_map.duplicate_distance_m >= 0,
        "target_map.duplicate_distance_m: must not be negative");
  check(c.target_map.earlier_observations_apart_m >= 0 &&
            c.target_map.earlier_observations_apart_m <= 1000,
        "target_map.earlier_observations_apart_m: must be in [0, 1000]");
  const auto& rf = loc.refinement;
  check(rf.max_points_per_segment >= 1, "refinement.max_points_per_segment: must be at least 1");
  check(rf.fine_distance_m > 0 && rf.coarse_distance_m >= rf.fine_distance_m,
        "refinement: need 0 < fine_distance_m <= coarse_distance_m");
  check(rf.kernel_scale_m > 0, "refinement.kernel_scale_m: must be positive");
  check(rf.max_correction_m > 0, "refinement.max_correction_m: must be positive");
  check(rf.neighbours_m >= 0, "refinement.neighbours_m: must not be negative");
  check(loc.latest_scan_fallback_m >= 0,
        "localization.latest_scan_fallback_m: must not be negative");
  check(lc.exclude_recent_m >= 0, "loop_closure.exclude_recent_m: must not be negative");
}

}  // namespace

namespace {

void readOdometrySection(const std::filesystem::path& path, const YAML::Node& root,
                         OdometryConfig& c) {
  std::string metric;
  readSection(path, root, "odometry",
              {{"voxel_size_m", set(c.voxel_size_m)},
               {"max_range_m", set(c.max_range_m)},
               {"min_range_m", set(c.min_range_m)},
               {"max_points_per_voxel", count(c.max_points_per_voxel, 1, 10000)},
               {"initial_threshold_m", set(c.initial_threshold_m)},
               {"min_motion_m", set(c.min_motion_m)},
               {"deskew", set(c.deskew)},
               {"min_points", count(c.min_points, 0, 100000000)},
               {"metric", set(metric)},
               {"max_iterations", count(c.icp.max_iterations, 1, 10000)},
               {"convergence", set(c.icp.convergence)},
               {"degeneracy_ratio", set(c.icp.degeneracy_ratio)},
               {"min_correspondences", count(c.icp.min_correspondences, 0, 100000000)}});
  auto check = [&](bool ok, const std::string& what) {
    if (!ok) throw std::runtime_error(path.string() + ": odometry." + what);
  };
  check(metric.empty() || metric == "point_to_plane" || metric == "point_to_point",
        "metric: expected point_to_plane or point_to_point, got '" + metric + "'");
  if (metric == "point_to_point") c.icp.metric = IcpMetric::kPointToPoint;
  check(c.voxel_size_m > 0, "voxel_size_m: must be positive");
  check(c.min_range_m >= 0 && c.max_range_m > c.min_range_m,
        "max_range_m: must exceed min_range_m (and that must not be negative)");
  check(c.max_points_per_voxel >= 1, "max_points_per_voxel: must be at least 1");
  check(c.initial_threshold_m > 0, "initial_threshold_m: must be positive");
  check(c.icp.max_iterations >= 1, "max_iterations: must be at least 1");
  check(c.icp.degeneracy_ratio >= 0, "degeneracy_ratio: must not be negative");
}

}  // namespace

namespace {

// A path written in a config file is relative to the config file, so that the config works from
// any directory.
std::string besideConfig(const std::filesystem::path& config, const std::string& file) {
  if (file.empty() || std::filesystem::path(file).is_absolute()) return file;
  return (config.parent_path() / file).lexically_normal().string();
}

// A model named by a config: beside the config as written; when no file is there (a shipped
// config copied elsewhere loses its ../models), the shipped model of that name, installed or in
// the source tree, said in one line. Missing everywhere, the path beside the config is kept and
// the model's loader refuses it by that name.
std::string modelBesideConfig(const std::filesystem::path& config, const std::string& file,
                              const char* key) {
  namespace fs = std::filesystem;
  const std::string beside = besideConfig(config, file);
  std::error_code ignored;
  if (beside.empty() || fs::path(file).is_absolute() || fs::exists(beside, ignored)) return beside;
  for (const fs::path& dir :
       {fs::path(SEMSEGMAP_INSTALLED_DATA_DIR), fs::path(SEMSEGMAP_SOURCE_DATA_DIR)}) {
    const fs::path shipped = dir / "models" / fs::path(file).filename();
    if (!fs::is_regular_file(shipped, ignored)) continue;
    note(config.string() + ": " + key + ": " + beside + " does not exist, using the shipped " +
         shipped.string());
    return shipped.string();
  }
  return beside;
}

void readSemanticsSection(const std::filesystem::path& path, const YAML::Node& root,
                          SemanticsConfig& c) {
  std::string resize, output, order;
  std::vector<float> mean, stddev;
  readSection(path, root, "semantics",
              {{"model", set(c.model)},
               {"class_map", set(c.class_map)},
               {"input_width", count(c.input_width, 0, kMaxCameraSide)},
               {"input_height", count(c.input_height, 0, kMaxCameraSide)},
               {"resize", set(resize)},
               {"mean", set(mean)},
               {"std", set(stddev)},
               {"channel_order", set(order)},
               {"output", set(output)},
               {"threads", count(c.threads, 0, 1024)},
               {"rate_hz", set(c.rate_hz)},
               {"tolerance_s", set(c.tolerance_s)},
               {"replace_dataset_labels", set(c.replace_dataset_labels)}});
  auto fail = [&](const std::string& what) {
    throw std::runtime_error(path.string() + ": semantics." + what);
  };
  try {
    if (!resize.empty()) c.resize = parseResizePolicy(resize);
  } catch (const std::invalid_argument& e) {
    fail(std::string("resize: ") + e.what());
  }
  try {
    if (!output.empty()) c.output = parseNetworkOutput(output);
  } catch (const std::invalid_argument& e) {
    fail(std::string("output: ") + e.what());
  }
  if (!order.empty() && order != "rgb" && order != "bgr")
    fail("channel_order: expected rgb or bgr, got '" + order + "'");
  c.bgr = order == "bgr";
  for (auto [values, key, target] :
       {std::tuple{&mean, "mean", &c.mean}, std::tuple{&stddev, "std", &c.std}}) {
    if (values->empty()) continue;
    if (values->size() != 3) fail(std::string(key) + ": expected 3 numbers (R, G, B)");
    std::copy(values->begin(), values->end(), target->begin());
  }
  for (float s : c.std)
    if (!(s > 0)) fail("std: must be positive");
  if ((c.input_width > 0) != (c.input_height > 0) || c.input_width < 0 || c.input_height < 0)
    fail("input_width, input_height: give both (positive) or neither");
  if (c.rate_hz < 0 || c.tolerance_s < 0) fail("rate_hz, tolerance_s: must not be negative");
  c.model = besideConfig(path, c.model);
  const std::filesystem::path map(c.class_map);
  if (map.has_parent_path() || map.extension() == ".yaml")
    c.class_map = besideConfig(path, c.class_map);
}

}  // namespace

SemanticsConfig loadSemanticsConfig(const std::filesystem::path& path) {
  SemanticsConfig c;
  readSemanticsSection(path, loadConfigRoot(path), c);
  return c;
}

OdometryConfig loadOdometryConfig(const std::filesystem::path& path) {
  OdometryConfig c;
  readOdometrySection(path, loadConfigRoot(path), c);
  return c;
}

PipelineConfig loadPipelineConfig(const std::filesystem::path& path) {
  const YAML::Node root = loadConfigRoot(path);
  PipelineConfig c;
  readSection(path, root, "enrichment",
              {{"occlusion_radius_px", count(c.enrichment.occlusion_radius_px, 0, 100)},
               {"occlusion_tolerance_m", set(c.enrichment.occlusion_tolerance_m)},
               {"occlusion_tolerance_rel", set(c.enrichment.occlusion_tolerance_rel)}});
  auto& lm = c.local_map;
  std::string dynamic_removal;
  readSection(path, root, "local_map",
              {{"voxel_size_m", set(lm.voxel_size_m)},
               {"dynamic_removal", set(dynamic_removal)},
               {"dynamic_vote_share", set(lm.dynamic_vote_share)},
               {"radius_m", set(lm.radius_m)},
               {"min_points_per_voxel", count(lm.min_points_per_voxel, 1, 1000000)},
               {"remove_dynamic_classes", set(lm.remove_dynamic_classes)},
               {"remove_ground_classes", set(lm.remove_ground_classes)},
               {"remove_unknown_class", set(lm.remove_unknown_class)},
               {"remove_unobserved", set(lm.remove_unobserved)},
               {"geometric_ground_removal", set(lm.geometric_ground_removal)},
               {"ground_cell_size_m", set(lm.ground.cell_size_m)},
               {"ground_neighbourhood_cells", count(lm.ground.neighbourhood_cells, 0, 100)},
               {"ground_height_above_m", set(lm.ground.height_above_m)}});
  try {
    if (!dynamic_removal.empty()) lm.dynamic_removal = parseDynamicRemoval(dynamic_removal);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path.string() + ": local_map.dynamic_removal: " + e.what());
  }
  auto& sg = c.segmentation;
  readSection(path, root, "segmentation",
              {{"d_segment_m", set(sg.d_segment_m)},
               {"hue_threshold", set(sg.hue_threshold)},
               {"hue_penalty", set(sg.hue_penalty)},
               {"class_penalty", set(sg.class_penalty)},
               {"min_segment_points", count(sg.min_segment_points, 0, kMaxPoints)},
               {"max_segment_points", count(sg.max_segment_points, 0, kMaxPoints)},
               {"observation_growth", set(sg.observation_growth)},
               {"keep_all_observation_points", set(sg.keep_all_observation_points)}});

  auto& d = c.descriptor;
  readSection(path, root, "descriptor",
              {{"kind", set(d.kind)},
               {"model", set(d.model)},
               {"model_lidar_only", set(d.model_lidar_only)},
               {"batch", count(d.batch, 1, 4096)}});
  d.model = modelBesideConfig(path, d.model, "descriptor.model");
  d.model_lidar_only = modelBesideConfig(path, d.model_lidar_only, "descriptor.model_lidar_only");
  auto& loc = c.localization;
  readSection(path, root, "localization",
              {{"k", count(loc.localizer.index.k, 1, 1000)},
               {"exact_below", count(loc.localizer.index.exact_below, 0, kMaxPoints)},
               {"resolution_m", set(loc.localizer.verification.resolution_m)},
               {"min_inliers", count(loc.localizer.verification.min_inliers, 3, 10000)},
               {"min_local_segments", count(loc.localizer.min_local_segments, 0, 1000000)},
               {"every_n_frames", count(loc.every_n_frames, 1, 1000000)},
               {"latest_scan_fallback_m", set(loc.latest_scan_fallback_m)}});
  auto& rf = loc.refinement;
  readSection(path, root, "refinement",
              {{"enabled", set(rf.enabled)},
               {"max_points_per_segment", count(rf.max_points_per_segment, 1, 1000000)},
               {"coarse_distance_m", set(rf.coarse_distance_m)},
               {"fine_distance_m", set(rf.fine_distance_m)},
               {"kernel_scale_m", set(rf.kernel_scale_m)},
               {"max_correction_m", set(rf.max_correction_m)},
               {"min_correspondences", count(rf.min_correspondences, 0, kMaxPoints)},
               {"neighbours_m", set(rf.neighbours_m)}});
  readSection(path, root, "target_map",
              {{"duplicate_distance_m", set(c.target_map.duplicate_distance_m)},
               // The map file stores a segment's point count in 16 bits (artefacts/map_file.cpp).
               {"max_points_per_segment", count(c.target_map.max_points_per_segment, 0, 65535)},
               {"earlier_observations_apart_m", set(c.target_map.earlier_observations_apart_m)}});
  auto& lc = c.loop_closure;
  readSection(path, root, "loop_closure",
              {{"exclude_recent_m", set(lc.exclude_recent_m)},
               {"min_travel_between_loops_m", set(lc.min_travel_between_loops_m)},
               {"odometry_translation_sigma_m", set(lc.graph.odometry_translation_sigma_m)},
               {"odometry_rotation_sigma_rad", set(lc.graph.odometry_rotation_sigma_rad)},
               {"loop_translation_sigma_m", set(lc.graph.loop_translation_sigma_m)},
               {"loop_rotation_sigma_rad", set(lc.graph.loop_rotation_sigma_rad)}});

  checkPipelineConfig(path, c);
  OdometryConfig odometry;  // checked here too, so that a typo fails every command
  readOdometrySection(path, root, odometry);
  SemanticsConfig semantics;
  readSemanticsSection(path, root, semantics);
  return c;
}

}  // namespace semsegmap
