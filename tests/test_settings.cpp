// The setting table (pipeline/setting_table.h) against what uses it: the config reader (every
// key, its limits, the old keys), the map parameters, and the shipped configs.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "error_text.h"
#include "semsegmap/core/diagnostics.h"
#include "semsegmap/core/exact_text.h"
#include "semsegmap/pipeline/map_parameters.h"
#include "semsegmap/pipeline/setting_table.h"
#include "semsegmap/settings/config.h"
#include "temp_dir.h"

namespace semsegmap {
namespace {

namespace fs = std::filesystem;
using test_support::errorOf;
using test_support::TempDir;

// YAML text of settings by key, nested as the keys are: {"a.b.c": "1"} -> "a:\n  b:\n    c: 1\n".
std::string nestedYaml(const std::map<std::string, std::string>& values) {
  struct Tree {
    std::map<std::string, Tree> children;
    std::string value;
  } root;
  for (const auto& [key, value] : values) {
    Tree* t = &root;
    for (size_t start = 0, dot = 0; dot != std::string::npos; start = dot + 1) {
      dot = key.find('.', start);
      t = &t->children[key.substr(start, dot - start)];
    }
    t->value = value;
  }
  std::string out;
  const auto emit = [&](const auto& self, const Tree& t, const std::string& indent) -> void {
    for (const auto& [name, child] : t.children) {
      out += indent + name + ":" + (child.children.empty() ? " " + child.value : "") + "\n";
      self(self, child, indent + "  ");
    }
  };
  emit(emit, root, "");
  return out;
}

std::string yamlText(const SettingValue& value) {
  if (const auto* text = std::get_if<std::string>(&value)) return "'" + *text + "'";
  return settingText(value);
}

// A value of `s` other than its default that passes every check.
SettingValue otherValue(const Setting& s) {
  const SettingValue d = s.get(Settings{});
  switch (s.kind) {
    case SettingKind::kFlag:
      return !std::get<bool>(d);
    case SettingKind::kCount: {
      const long long v = std::get<long long>(d);
      return v + 1 <= s.hi ? v + 1 : v - 1;
    }
    case SettingKind::kNumber: {
      // A share whose default lies near 1 (ambiguity_ratio) stays a share.
      const double v = std::get<double>(d);
      return v > 0.875 && v <= 1.0 ? v - 0.125 : v + 0.125;
    }
    // Absolute, so that it is not taken relative to the config file.
    case SettingKind::kText:
      return "/elsewhere/" + s.key;
    case SettingKind::kChoice:
      return s.choices[0] == std::get<std::string>(d) ? s.choices[1] : s.choices[0];
    case SettingKind::kTriple:
      return std::array<float, 3>{0.25f, 0.5f, 0.75f};
  }
  return d;
}

// The settings `key` needs beside it to pass the cross-field checks.
std::map<std::string, std::string> withCompanions(const std::string& key,
                                                  const std::string& value) {
  std::map<std::string, std::string> values = {{key, value}};
  if (key == "semantics.input_width") values["semantics.input_height"] = "8";
  if (key == "semantics.input_height") values["semantics.input_width"] = "8";
  if (key == "descriptor.model_lidar_only") values["descriptor.model"] = "/elsewhere/model";
  if (key == "descriptor.keypoints") values["descriptor.kind"] = "3dsmoothnet";
  return values;
}

// Every setting of `s` as text, by key.
std::map<std::string, std::string> dump(const Settings& s) {
  std::map<std::string, std::string> out;
  for (const Setting& setting : settingTable()) out[setting.key] = settingText(setting.get(s));
  return out;
}

TEST(SettingTable, KeysAreUniqueAndEveryOneIsDescribed) {
  std::set<std::string> keys;
  for (const Setting& s : settingTable()) {
    EXPECT_TRUE(keys.insert(s.key).second) << s.key;
    EXPECT_FALSE(s.description.empty()) << s.key;
    EXPECT_EQ(s.description.find('\n'), std::string::npos) << s.key;
    if (s.kind == SettingKind::kCount) {
      EXPECT_LE(s.lo, s.hi) << s.key;
    }
    if (s.kind == SettingKind::kChoice) {
      EXPECT_GE(s.choices.size(), 2u) << s.key;
    }
  }
}

TEST(SettingTable, EverySettingLoadsIntoTheFieldItsKeyNames) {
  TempDir tmp;
  const fs::path file = tmp.path() / "c.yaml";
  const auto defaults = dump(Settings{});
  for (const Setting& s : settingTable()) {
    const SettingValue value = otherValue(s);
    const auto values = withCompanions(s.key, yamlText(value));
    std::ofstream(file) << nestedYaml(values);
    Settings loaded;
    ASSERT_NO_THROW(loaded = loadSettings(file)) << nestedYaml(values);
    EXPECT_EQ(settingText(s.get(loaded)), settingText(value)) << s.key;
    EXPECT_NE(settingText(value), defaults.at(s.key)) << s.key;
    for (const auto& [key, text] : dump(loaded))  // and nothing else changed
      if (!values.count(key)) {
        EXPECT_EQ(text, defaults.at(key)) << s.key << " changed " << key;
      }
  }
}

TEST(SettingTable, AValueOutOfItsLimitsIsRefusedNamingTheFileAndTheKey) {
  TempDir tmp;
  const fs::path file = tmp.path() / "c.yaml";
  for (const Setting& s : settingTable()) {
    std::vector<std::string> bad;
    switch (s.kind) {
      case SettingKind::kFlag:
        bad = {"maybe", "[true]"};
        break;
      case SettingKind::kCount:
        bad = {std::to_string(s.hi + 1), std::to_string(s.lo - 1), "1.5", "many"};
        break;
      case SettingKind::kNumber:
        bad = {".inf", ".nan", "far", "[1]"};
        break;
      case SettingKind::kText:
        bad = {"[a, b]", "{a: b}"};
        break;
      case SettingKind::kChoice:
        bad = {"nonsense", "[a]"};
        break;
      case SettingKind::kTriple:
        bad = {"[0.5, .nan, 0.5]", "[1, 2]", "0.5"};
        break;
    }
    for (const std::string& value : bad) {
      std::ofstream(file) << nestedYaml({{s.key, value}});
      const std::string error = errorOf([&] { loadSettings(file); });
      EXPECT_EQ(error.rfind(file.string() + ": " + s.key + ": ", 0), 0u) << value << ": " << error;
      EXPECT_ONE_LINE(error);
    }
  }
}

TEST(SettingTable, AnUnknownKeyIsRefusedWithTheNearestName) {
  TempDir tmp;
  const fs::path file = tmp.path() / "c.yaml";
  const auto error = [&](const std::string& yaml) {
    std::ofstream(file) << yaml;
    return errorOf([&] { loadSettings(file); });
  };
  EXPECT_EQ(error("segmentation:\n  d_segmnt_m: 0.3\n"),
            file.string() + ": segmentation.d_segmnt_m: unknown key (did you mean d_segment_m?)");
  EXPECT_EQ(error("localization:\n  localizer:\n    indx:\n      k: 3\n"),
            file.string() + ": localization.localizer.indx: unknown key (did you mean index?)");
  EXPECT_EQ(error("segmentaton:\n  d_segment_m: 0.3\n"),
            file.string() + ": segmentaton: unknown section (did you mean segmentation?)");
  EXPECT_EQ(error("localization:\n  localizer: 3\n"),
            file.string() + ": localization.localizer: expected a mapping");
  EXPECT_EQ(error("localization:\n  k: 3\n  localizer:\n    index:\n      k: 4\n"),
            file.string() + ": localization.localizer.index.k: set twice (also as localization.k)");
}

TEST(SettingAliases, EveryOldKeyNamesASettingAndIsNoneItself) {
  std::set<std::string> old;
  for (const SettingAlias& a : settingAliases()) {
    EXPECT_TRUE(old.insert(a.old_key).second) << a.old_key;
    EXPECT_NE(findSetting(a.key), nullptr) << a.old_key << " -> " << a.key;
    EXPECT_EQ(findSetting(a.old_key), nullptr) << a.old_key;
    EXPECT_FALSE(isSettingGroup(a.old_key)) << a.old_key;
    EXPECT_EQ(currentSettingKey(a.old_key), a.key);
  }
}

// Collects the notes and warnings of its lifetime.
class Messages {
 public:
  Messages() {
    setMessageSink([this](const std::string& line) { lines_.push_back(line); });
  }
  ~Messages() { setMessageSink({}); }
  const std::vector<std::string>& lines() const { return lines_; }

 private:
  std::vector<std::string> lines_;
};

TEST(SettingAliases, AConfigInOldKeysLoadsAsTheSameInNewKeysSayingSoOnce) {
  TempDir tmp;
  std::map<std::string, std::string> old_keys, new_keys;
  for (const SettingAlias& a : settingAliases()) {
    const std::string value = yamlText(otherValue(*findSetting(a.key)));
    old_keys[a.old_key] = value;
    new_keys[a.key] = value;
  }
  const fs::path old_file = tmp.path() / "old.yaml", new_file = tmp.path() / "new.yaml";
  std::ofstream(old_file) << nestedYaml(old_keys);
  std::ofstream(new_file) << nestedYaml(new_keys);
  Messages messages;
  const auto from_new = dump(loadSettings(new_file));
  EXPECT_TRUE(messages.lines().empty());
  EXPECT_EQ(dump(loadSettings(old_file)), from_new);
  loadOdometryConfig(old_file);  // the same file again: no second note
  loadPipelineConfig(old_file);
  ASSERT_EQ(messages.lines().size(), 1u);
  const std::string& note = messages.lines()[0];
  EXPECT_MENTIONS(note, old_file.string() + ": old keys");
  for (const SettingAlias& a : settingAliases()) EXPECT_MENTIONS(note, a.old_key + " -> " + a.key);
}

// tests/old_key_configs/ holds the shipped configs as they were before their keys were renamed:
// each loads to exactly what the shipped one does, and no shipped config uses an old key.
TEST(SettingAliases, TheShippedConfigsLoadAsTheirOldKeyVersions) {
  TempDir tmp;
  const fs::path source(SEMSEGMAP_SOURCE_DIR);
  size_t compared = 0;
  Messages messages;
  for (const auto& entry : fs::directory_iterator(source / "config")) {
    if (entry.path().extension() != ".yaml") continue;
    const fs::path name = entry.path().filename();
    ASSERT_TRUE(fs::exists(source / "tests" / "old_key_configs" / name)) << name;
    // Side by side, so that their relative model paths resolve alike.
    fs::create_directories(tmp.path() / "old");
    fs::create_directories(tmp.path() / "new");
    fs::copy_file(source / "tests" / "old_key_configs" / name, tmp.path() / "old" / name);
    fs::copy_file(entry.path(), tmp.path() / "new" / name);
    EXPECT_EQ(dump(loadSettings(tmp.path() / "old" / name)),
              dump(loadSettings(tmp.path() / "new" / name)))
        << name;
    ++compared;
  }
  EXPECT_GE(compared, 8u);
  for (const std::string& line : messages.lines())
    if (line.find("old keys") != std::string::npos) {
      EXPECT_EQ(line.find("/new/"), std::string::npos) << line;
    }
}

// The settings a map records are the ones it recorded before the table (by meaning: under their
// names now), and a map that recorded them under the old names is read as recording these.
TEST(SettingAliases, AMapRecordingOldNamesIsAcceptedWithTheSameConfig) {
  const std::vector<std::string> recorded_before = {"enrichment.occlusion_radius_px",
                                                    "enrichment.occlusion_tolerance_m",
                                                    "enrichment.occlusion_tolerance_rel",
                                                    "local_map.voxel_size_m",
                                                    "local_map.radius_m",
                                                    "local_map.min_points_per_voxel",
                                                    "local_map.remove_dynamic_classes",
                                                    "local_map.dynamic_removal",
                                                    "local_map.dynamic_vote_share",
                                                    "local_map.remove_ground_classes",
                                                    "local_map.remove_unknown_class",
                                                    "local_map.remove_unobserved",
                                                    "local_map.geometric_ground_removal",
                                                    "local_map.ground_cell_size_m",
                                                    "local_map.ground_neighbourhood_cells",
                                                    "local_map.ground_height_above_m",
                                                    "segmentation.d_segment_m",
                                                    "segmentation.hue_threshold",
                                                    "segmentation.hue_penalty",
                                                    "segmentation.class_penalty",
                                                    "segmentation.min_segment_points",
                                                    "segmentation.max_segment_points",
                                                    "segmentation.observation_growth"};
  PipelineConfig config =
      loadPipelineConfig(fs::path(SEMSEGMAP_SOURCE_DIR) / "config" / "lidar-camera.yaml");
  config.local_map.ground.cell_size_m = 0.75;
  const MapParameters now = mapParametersOf(config);
  ASSERT_EQ(now.size(), recorded_before.size());
  MapParameters old;
  for (size_t i = 0; i < now.size(); ++i) {
    EXPECT_EQ(now[i].first, currentSettingKey(recorded_before[i]));
    old.emplace_back(recorded_before[i], now[i].second);
  }
  EXPECT_EQ(upgradeMapParameters(old), now);
  TargetMap map;
  map.parameters = old;
  EXPECT_NO_THROW(checkMapParameters("old.map", map, config, MapSettingsCheck::kRefuse));
  config.local_map.ground.cell_size_m = 1.5;
  EXPECT_MENTIONS(
      errorOf([&] { checkMapParameters("old.map", map, config, MapSettingsCheck::kRefuse); }),
      "old.map: local_map.ground.cell_size_m: the map was built with 0.75");
}

}  // namespace
}  // namespace semsegmap
