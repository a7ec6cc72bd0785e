#include "semsegmap/settings/config.h"

#include "semsegmap/core/diagnostics.h"
#include "semsegmap/core/nearest_name.h"
#include "semsegmap/core/shown_text.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace semsegmap {

namespace {

// Every setting is read through the table (pipeline/setting_table.h): anything not in it is an
// error, so a typo in a config never silently leaves a default in place.

// A value of the wrong type or out of its limits: the reader adds the file and the key.
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
  if (!ok)
    throw BadValue{std::string("wrong type: expected ") + expected<T>() + ", got " + shown(n)};
  return value;
}

// Counts have limits, so that no count read from a file can make the program allocate what it
// says (localization.k: 1000000000 was std::bad_alloc).
long long decodeCount(const YAML::Node& n, long long lo, long long hi) {
  long long value = 0;
  bool ok = n.IsScalar();
  try {
    ok = ok && YAML::convert<long long>::decode(n, value);
  } catch (const YAML::Exception&) {
    ok = false;
  }
  if (!ok || value < lo || value > hi)
    throw BadValue{"wrong type: expected an integer in [" + std::to_string(lo) + ", " +
                   std::to_string(hi) + "], got " + shown(n)};
  return value;
}

std::string decodeChoice(const YAML::Node& n, const std::vector<std::string>& choices) {
  const std::string value = decode<std::string>(n);
  if (std::find(choices.begin(), choices.end(), value) != choices.end()) return value;
  std::string names;
  for (size_t i = 0; i < choices.size(); ++i)
    names += (i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + choices[i];
  throw BadValue{"expected " + names + ", got '" + shownText(value) + "'"};
}

std::array<float, 3> decodeTriple(const YAML::Node& n) {
  const auto values = decode<std::vector<float>>(n);
  if (values.size() != 3) throw BadValue{"expected 3 numbers (R, G, B)"};
  return {values[0], values[1], values[2]};
}

SettingValue decodeSetting(const Setting& s, const YAML::Node& n) {
  switch (s.kind) {
    case SettingKind::kFlag:
      return decode<bool>(n);
    case SettingKind::kCount:
      return decodeCount(n, s.lo, s.hi);
    case SettingKind::kNumber:
      return decode<double>(n);
    case SettingKind::kText:
      return decode<std::string>(n);
    case SettingKind::kChoice:
      return decodeChoice(n, s.choices);
    case SettingKind::kTriple:
      return decodeTriple(n);
  }
  throw BadValue{"an unknown kind of setting"};
}

std::string keyOf(const std::filesystem::path& path, const YAML::Node& key,
                  const std::string& where) {
  if (!key.IsScalar())
    throw std::runtime_error(path.string() + ": " + where + ": a key that is " + shown(key));
  return shownText(key.Scalar(), std::string::npos);  // a key is shown in messages as it is
}

std::string joined(const std::string& prefix, const std::string& name) {
  return prefix.empty() ? name : prefix + "." + name;
}

// "<file>: segmentation.d_segmnt_m: unknown key (did you mean d_segment_m?)".
[[noreturn]] void failUnknown(const std::filesystem::path& path, const std::string& prefix,
                              const std::string& name) {
  const std::string nearest = nearestName(name, settingNamesBelow(prefix));
  throw std::runtime_error(path.string() + ": " + joined(prefix, name) +
                           (prefix.empty() ? ": unknown section" : ": unknown key") +
                           (nearest.empty() ? "" : " (did you mean " + nearest + "?)"));
}

// What one file sets: each setting once (under its old key or its new one, not both).
struct Reading {
  std::filesystem::path path;
  Settings settings;
  std::map<std::string, std::string> written_as;  // key -> the key the file used
};

void readSetting(Reading& r, const Setting& s, const std::string& written, const YAML::Node& n) {
  const auto [it, first] = r.written_as.emplace(s.key, written);
  if (!first)
    throw std::runtime_error(r.path.string() + ": " + written + ": set twice (also as " +
                             it->second + ")");
  try {
    s.set(r.settings, decodeSetting(s, n));
  } catch (const BadValue& e) {
    throw std::runtime_error(r.path.string() + ": " + written + ": " + e.what);
  }
}

// The settings of the mapping `node` at `prefix` ("localization.localizer"), nested as the
// structs are; old keys are read as their new ones.
void readMapping(Reading& r, const YAML::Node& node, const std::string& prefix) {
  for (const auto& kv : node) {
    const std::string name = keyOf(r.path, kv.first, prefix);
    const std::string written = joined(prefix, name);
    if (const Setting* s = findSetting(currentSettingKey(written))) {
      readSetting(r, *s, written, kv.second);
    } else if (!isSettingGroup(written)) {
      failUnknown(r.path, prefix, name);
    } else if (!kv.second.IsMap()) {
      throw std::runtime_error(r.path.string() + ": " + written + ": expected a mapping");
    } else {
      readMapping(r, kv.second, written);
    }
  }
}

// The old keys `node` uses (all of them, whichever sections are read).
void collectOldKeys(const YAML::Node& node, const std::string& prefix,
                    std::vector<std::string>& old) {
  if (!node.IsMap()) return;
  for (const auto& kv : node) {
    if (!kv.first.IsScalar()) continue;
    const std::string key = joined(prefix, kv.first.Scalar());
    if (currentSettingKey(key) != key)
      old.push_back(key);
    else
      collectOldKeys(kv.second, key, old);
  }
}

// One line per file (a file is read by several loaders), naming its old keys and their names now.
void noteOldKeys(const std::filesystem::path& path, const YAML::Node& root) {
  std::vector<std::string> old;
  collectOldKeys(root, "", old);
  if (old.empty()) return;
  static std::mutex mutex;
  static std::set<std::string> noted;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (!noted.insert(path.lexically_normal().string()).second) return;
  }
  std::string text = path.string() + ": old keys, read as their names now:";
  for (size_t i = 0; i < old.size(); ++i)
    text += (i ? ", " : " ") + old[i] + " -> " + currentSettingKey(old[i]);
  note(text);
}

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
  for (const auto& kv : root) {
    const std::string key = keyOf(path, kv.first, "the top level");
    if (!isSettingGroup(key)) failUnknown(path, "", key);
  }
  noteOldKeys(path, root);
  return root;
}

}  // namespace

namespace {

void checkRelocalizationSettings(const std::filesystem::path& path, const RelocalizationConfig& c) {
  auto check = [&](bool ok, const std::string& what) {
    if (!ok) throw std::runtime_error(path.string() + ": localization.relocalization." + what);
  };
  check(c.after_m >= 0, "after_m: must not be negative");
  check(c.jump_m > 0 && c.jump_deg > 0, "jump_m, jump_deg: must be positive");
  check(c.place_radius_m > 0 && c.cell_m > 0, "place_radius_m, cell_m: must be positive");
  check(c.cell_m <= c.place_radius_m, "cell_m: must not exceed place_radius_m");
  check(c.verification.resolution_m > 0 && c.verification.inlier_tolerance_m > 0,
        "verification: resolution_m and inlier_tolerance_m must be positive");
  check(c.verification.min_spread_m >= 0, "verification.min_spread_m: must not be negative");
  const RegistrationCheckConfig& r = c.check;
  check(r.fine_distance_m > 0 && r.coarse_distance_m >= r.fine_distance_m,
        "check: need 0 < fine_distance_m <= coarse_distance_m");
  check(r.retry_coarse_distance_m == 0 || (r.retry_coarse_distance_m >= r.fine_distance_m &&
                                           r.retry_coarse_distance_m < r.coarse_distance_m),
        "check.retry_coarse_distance_m: 0, or in [fine_distance_m, coarse_distance_m)");
  check(r.kernel_scale_m > 0 && r.near_m > 0 && r.place_radius_m > 0,
        "check: kernel_scale_m, near_m and place_radius_m must be positive");
  check(r.min_fitness >= 0 && r.min_fitness <= 1, "check.min_fitness: must be in [0, 1]");
  check(r.max_correction_m > 0 && r.max_correction_deg > 0,
        "check: max_correction_m and max_correction_deg must be positive");
  check(r.max_tilt_deg > 0 && r.max_tilt_deg <= 180, "check.max_tilt_deg: must be in (0, 180]");
  check(c.scan_context_max_distance >= 0 && c.scan_context_max_distance <= 1,
        "scan_context_max_distance: must be in [0, 1]");
  check(c.scan_context_min_fitness >= 0 && c.scan_context_min_fitness <= 1,
        "scan_context_min_fitness: must be in [0, 1]");
  check(c.ambiguity_ratio > 0 && c.ambiguity_ratio <= 1, "ambiguity_ratio: must be in (0, 1]");
  check(c.scan_context_distinct_ratio >= 0 && c.scan_context_distinct_ratio <= 1,
        "scan_context_distinct_ratio: must be in [0, 1]");
}

void checkCovarianceSettings(const std::filesystem::path& path, const PoseCovarianceConfig& c) {
  auto check = [&](bool ok, const std::string& what) {
    if (!ok) throw std::runtime_error(path.string() + ": localization.covariance." + what);
  };
  check(c.registration_inflation > 0 && c.centroid_inflation > 0,
        "registration_inflation, centroid_inflation: must be positive");
  check(c.min_sigma_m >= 0 && c.min_sigma_deg >= 0,
        "min_sigma_m, min_sigma_deg: must not be negative");
  check(c.max_sigma_m > c.min_sigma_m && c.max_sigma_deg > c.min_sigma_deg,
        "max_sigma_m, max_sigma_deg: must exceed the floors");
  check(c.degeneracy_ratio >= 0 && c.degeneracy_ratio < 1, "degeneracy_ratio: must be in [0, 1)");
}

// The cross-field checks and the limits a number has beyond being finite, of the sections read.
void checkPipelineSettings(const std::filesystem::path& path, const Settings& c) {
  const auto& lm = c.local_map;
  const auto& sg = c.segmentation;
  const auto& d = c.descriptor;
  const auto& loc = c.localization;
  const auto& vf = loc.localizer.verification;
  auto check = [&](bool ok, const std::string& what) {
    if (!ok) throw std::runtime_error(path.string() + ": " + what);
  };
  check(lm.voxel_size_m > 0, "local_map.voxel_size_m: must be positive");
  check(lm.radius_m > lm.voxel_size_m, "local_map.radius_m: must exceed the voxel size");
  check(lm.dynamic_vote_share >= 0 && lm.dynamic_vote_share < 1,
        "local_map.dynamic_vote_share: must be in [0, 1)");
  check(sg.d_segment_m > 0, "segmentation.d_segment_m: must be positive");
  check(sg.hue_threshold >= 0 && sg.hue_threshold <= 0.5,
        "segmentation.hue_threshold: must be in [0, 0.5]");
  check(sg.hue_penalty >= 0 && sg.class_penalty >= 0,
        "segmentation: penalties must not be negative");
  check(sg.min_segment_points <= sg.max_segment_points,
        "segmentation.min_segment_points: must not exceed max_segment_points");
  check(d.keypoints == 0 || d.kind == "3dsmoothnet", "descriptor.keypoints: only for 3dsmoothnet");
  check(d.model_lidar_only.empty() || !d.model.empty(),
        "descriptor.model_lidar_only: only for a learned descriptor (one with a model)");
  check(vf.resolution_m > 0, "localization.localizer.verification.resolution_m: must be positive");
  check(vf.inlier_tolerance_m > 0,
        "localization.localizer.verification.inlier_tolerance_m: must be positive");
  check(vf.min_spread_m >= 0,
        "localization.localizer.verification.min_spread_m: must not be negative");
  check(c.target_map.duplicate_distance_m >= 0,
        "target_map.duplicate_distance_m: must not be negative");
  check(c.target_map.earlier_observations_apart_m >= 0 &&
            c.target_map.earlier_observations_apart_m <= 1000,
        "target_map.earlier_observations_apart_m: must be in [0, 1000]");
  check(c.target_map.scan_context_apart_m >= 0,
        "target_map.scan_context_apart_m: must not be negative");
  const auto& rf = loc.refinement;
  check(rf.fine_distance_m > 0 && rf.coarse_distance_m >= rf.fine_distance_m,
        "localization.refinement: need 0 < fine_distance_m <= coarse_distance_m");
  check(rf.kernel_scale_m > 0, "localization.refinement.kernel_scale_m: must be positive");
  check(rf.max_correction_m > 0, "localization.refinement.max_correction_m: must be positive");
  check(rf.neighbours_m >= 0, "localization.refinement.neighbours_m: must not be negative");
  check(loc.latest_scan_fallback_m >= 0,
        "localization.latest_scan_fallback_m: must not be negative");
  check(c.loop_closure.exclude_recent_m >= 0,
        "loop_closure.exclude_recent_m: must not be negative");
  checkRelocalizationSettings(path, loc.relocalization);
  checkCovarianceSettings(path, loc.covariance);
}

void checkOdometrySettings(const std::filesystem::path& path, const OdometryConfig& c) {
  auto check = [&](bool ok, const std::string& what) {
    if (!ok) throw std::runtime_error(path.string() + ": odometry." + what);
  };
  check(c.voxel_size_m > 0, "voxel_size_m: must be positive");
  check(c.min_range_m >= 0 && c.max_range_m > c.min_range_m,
        "max_range_m: must exceed min_range_m (and that must not be negative)");
  check(c.initial_threshold_m > 0, "initial_threshold_m: must be positive");
  check(c.min_threshold_m >= 0, "min_threshold_m: must not be negative");
  check(c.icp.degeneracy_ratio >= 0, "icp.degeneracy_ratio: must not be negative");
}

void checkSemanticsSettings(const std::filesystem::path& path, const SemanticsConfig& c) {
  auto check = [&](bool ok, const std::string& what) {
    if (!ok) throw std::runtime_error(path.string() + ": semantics." + what);
  };
  for (float s : c.std) check(s > 0, "std: must be positive");
  check((c.input_width > 0) == (c.input_height > 0),
        "input_width, input_height: give both (positive) or neither");
  check(c.rate_hz >= 0 && c.tolerance_s >= 0 && c.budget_cores >= 0 && c.latency_s >= 0,
        "rate_hz, budget_cores, tolerance_s, latency_s: must not be negative");
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

// The settings that convert after reading: files named relative to the config file.
void resolvePaths(const std::filesystem::path& path, Settings& c, bool pipeline, bool semantics) {
  if (pipeline) {
    auto& d = c.descriptor;
    d.model = modelBesideConfig(path, d.model, "descriptor.model");
    d.model_lidar_only = modelBesideConfig(path, d.model_lidar_only, "descriptor.model_lidar_only");
  }
  if (semantics) {
    c.semantics.model = besideConfig(path, c.semantics.model);
    const std::filesystem::path map(c.semantics.class_map);
    if (map.has_parent_path() || map.extension() == ".yaml")
      c.semantics.class_map = besideConfig(path, c.semantics.class_map);
  }
}

// The sections a loader reads: the pipeline's (every section but odometry and semantics), the
// odometry's, the semantics'. Every section name is checked whichever are read.
enum class Sections { kAll, kOdometry, kSemantics };

bool reads(Sections sections, const std::string& section) {
  if (sections == Sections::kAll) return true;
  return section == (sections == Sections::kOdometry ? "odometry" : "semantics");
}

Settings readSettings(const std::filesystem::path& path, Sections sections) {
  const YAML::Node root = loadConfigRoot(path);
  Reading r{path, {}, {}};
  for (const auto& kv : root) {
    const std::string section = kv.first.Scalar();
    if (!reads(sections, section)) continue;
    if (!kv.second.IsMap())
      throw std::runtime_error(path.string() + ": " + section + ": expected a mapping");
    readMapping(r, kv.second, section);
  }
  resolvePaths(path, r.settings, sections == Sections::kAll, reads(sections, "semantics"));
  if (sections == Sections::kAll) checkPipelineSettings(path, r.settings);
  if (reads(sections, "odometry")) checkOdometrySettings(path, r.settings.odometry);
  if (reads(sections, "semantics")) checkSemanticsSettings(path, r.settings.semantics);
  return r.settings;
}

}  // namespace

Settings loadSettings(const std::filesystem::path& path) {
  return readSettings(path, Sections::kAll);
}

SemanticsConfig loadSemanticsConfig(const std::filesystem::path& path) {
  return readSettings(path, Sections::kSemantics).semantics;
}

OdometryConfig loadOdometryConfig(const std::filesystem::path& path) {
  return readSettings(path, Sections::kOdometry).odometry;
}

PipelineConfig loadPipelineConfig(const std::filesystem::path& path) {
  // The odometry and semantics sections are read and checked too, so that a typo fails every
  // command.
  return loadSettings(path);
}

}  // namespace semsegmap
