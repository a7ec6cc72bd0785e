#include "semsegmap/pipeline/map_parameters.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "semsegmap/core/diagnostics.h"
#include "semsegmap/pipeline/setting_table.h"

namespace semsegmap {

// The one place where settings that older builds recorded under other rules are read as this
// build would have recorded them.
MapParameters upgradeMapParameters(MapParameters recorded) {
  // Settings recorded under an old key (local_map.ground_cell_size_m) by their key now.
  for (auto& [key, value] : recorded) key = currentSettingKey(key);
  const auto find = [&](const std::string& key) {
    return std::find_if(recorded.begin(), recorded.end(),
                        [&](const auto& kv) { return kv.first == key; });
  };
  // Before unobserved points were told apart from class unknown, remove_unknown_class dropped
  // both: such a map was built with remove_unobserved equal to it.
  const auto unknown = find("local_map.remove_unknown_class");
  if (unknown != recorded.end() && find("local_map.remove_unobserved") == recorded.end())
    recorded.insert(unknown + 1, {"local_map.remove_unobserved", unknown->second});
  return recorded;
}

MapParameters mapParametersOf(const PipelineConfig& config) {
  Settings settings;
  static_cast<PipelineConfig&>(settings) = config;
  MapParameters recorded;
  for (const Setting& s : settingTable())
    if (s.recorded) recorded.emplace_back(s.key, settingText(s.get(settings)));
  return recorded;
}

void checkMapParameters(const std::string& map_name, const TargetMap& map,
                        const PipelineConfig& config, MapSettingsCheck check,
                        const std::string& remedy) {
  if (map.parameters.empty()) return;
  const auto differences =
      mapParameterDifferences(upgradeMapParameters(map.parameters), mapParametersOf(config));
  if (differences.empty()) return;
  if (check == MapSettingsCheck::kRefuse)
    throw std::runtime_error(describeDifference(map_name, differences.front()) + " (" + remedy +
                             ")");
  warn("localizing against a map built with other settings (" + std::to_string(differences.size()) +
       " differ):");
  for (const MapParameterDifference& d : differences) warn("  " + describeDifference(map_name, d));
}

}  // namespace semsegmap
