// Every setting of a config file, declared once: its key, which is its member path in the config
// structs (and its attribute path in Python), its type and limits, whether a target map records
// it, and what it does. settings/config.cpp reads YAML through this table, map_parameters.cpp
// records and compares maps through it, and the tests hold the Python binding and its stubs to it.
//
// The YAML nests as the structs do (`localization: {localizer: {index: {k: 16}}}`) rather than
// the structs being flattened for shorter keys: each nested struct is a stage's own config
// (LocalizerConfig is what a Localizer takes, PoseGraphConfig what the pose graph takes), and a
// flat pipeline config would have to be copied into them field by field, a sixth place to spell
// every setting.
//
// Old keys (what configs of the past used) are mapped to the new ones in one alias table, which
// also renames the settings recorded in old map files. It lives here, not in io/, because the
// pipeline records map parameters and may include nothing from io/ (docs/architecture.md).
#pragma once

#include <array>
#include <functional>
#include <string>
#include <variant>
#include <vector>

#include "semsegmap/odometry/lidar_odometry.h"
#include "semsegmap/pipeline/pipeline_config.h"
#include "semsegmap/semantics/segmentation_network.h"

namespace semsegmap {

// Everything a config file sets: the pipeline's sections at the top, the LiDAR odometry's and
// the segmentation network's beside them, so that every key is a member path from here.
struct Settings : PipelineConfig {
  OdometryConfig odometry;
  SemanticsConfig semantics;
};

enum class SettingKind {
  kFlag,    // true or false
  kCount,   // an integer in [lo, hi]: no file can make the program allocate what it says
  kNumber,  // a finite number (further limits are the checks of settings/config.cpp)
  kText,    // a string (file names are taken relative to the config file by settings/config.cpp)
  kChoice,  // one of `choices` (an enum, or a value converted to another field)
  kTriple,  // three finite numbers, R G B
};

using SettingValue = std::variant<bool, long long, double, std::string, std::array<float, 3>>;

struct Setting {
  std::string key;  // "section.member.path"
  SettingKind kind = SettingKind::kNumber;
  long long lo = 0, hi = 0;          // kCount
  std::vector<std::string> choices;  // kChoice
  // Recorded in a target map's parameters (pipeline/map_parameters.h): the settings the map's
  // segments depend on.
  bool recorded = false;
  std::string description;
  std::function<SettingValue(const Settings&)> get;
  // `value` is of the setting's kind and within its limits (settings/config.cpp checks them).
  std::function<void(Settings&, const SettingValue&)> set;
};

// In the order a map records them and a dump lists them.
const std::vector<Setting>& settingTable();
// nullptr when `key` names no setting.
const Setting* findSetting(const std::string& key);

struct SettingAlias {
  std::string old_key;  // a key configs of the past used
  std::string key;      // its name now
};
const std::vector<SettingAlias>& settingAliases();
// The key now for `key`: the alias's new name, or `key` itself.
std::string currentSettingKey(const std::string& key);
// Whether `path` is a section or nested struct of settings (old or new): "localization",
// "localization.localizer", "refinement".
bool isSettingGroup(const std::string& path);
// The names one level below `path` (a group, or "" for the sections), old ones included: what a
// mistyped key there may have been meant as.
std::vector<std::string> settingNamesBelow(const std::string& path);

// Text that reads back as exactly `value`: equal text is an equal setting.
std::string settingText(const SettingValue& value);

}  // namespace semsegmap
