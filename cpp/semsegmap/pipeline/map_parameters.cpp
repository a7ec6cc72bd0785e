#include "semsegmap/pipeline/map_parameters.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "semsegmap/core/diagnostics.h"
#include "semsegmap/core/exact_text.h"

namespace semsegmap {

namespace {

// Text that reads back as exactly `value`: equal text is equal settings.
std::string exact(double value) {
  return formatExactDouble(value);
}
std::string exact(bool value) {
  return value ? "true" : "false";
}
template <typename Integer, typename = std::enable_if_t<std::is_integral_v<Integer>>>
std::string exact(Integer value) {
  return std::to_string(value);
}

}  // namespace

// The one place where settings that older builds recorded under other rules are read as this
// build would have recorded them.
MapParameters upgradeMapParameters(MapParameters recorded) {
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
  const EnrichmentConfig& e = config.enrichment;
  const LocalMapConfig& lm = config.local_map;
  const SegmentationConfig& s = config.segmentation;
  return {
      {"enrichment.occlusion_radius_px", exact(e.occlusion_radius_px)},
      {"enrichment.occlusion_tolerance_m", exact(e.occlusion_tolerance_m)},
      {"enrichment.occlusion_tolerance_rel", exact(e.occlusion_tolerance_rel)},
      {"local_map.voxel_size_m", exact(lm.voxel_size_m)},
      {"local_map.radius_m", exact(lm.radius_m)},
      {"local_map.min_points_per_voxel", exact(lm.min_points_per_voxel)},
      {"local_map.remove_dynamic_classes", exact(lm.remove_dynamic_classes)},
      {"local_map.dynamic_removal", dynamicRemovalName(lm.dynamic_removal)},
      {"local_map.dynamic_vote_share", exact(lm.dynamic_vote_share)},
      {"local_map.remove_ground_classes", exact(lm.remove_ground_classes)},
      {"local_map.remove_unknown_class", exact(lm.remove_unknown_class)},
      {"local_map.remove_unobserved", exact(lm.remove_unobserved)},
      {"local_map.geometric_ground_removal", exact(lm.geometric_ground_removal)},
      {"local_map.ground_cell_size_m", exact(lm.ground.cell_size_m)},
      {"local_map.ground_neighbourhood_cells", exact(lm.ground.neighbourhood_cells)},
      {"local_map.ground_height_above_m", exact(lm.ground.height_above_m)},
      {"segmentation.d_segment_m", exact(s.d_segment_m)},
      {"segmentation.hue_threshold", exact(s.hue_threshold)},
      {"segmentation.hue_penalty", exact(s.hue_penalty)},
      {"segmentation.class_penalty", exact(s.class_penalty)},
      {"segmentation.min_segment_points", exact(s.min_segment_points)},
      {"segmentation.max_segment_points", exact(s.max_segment_points)},
      {"segmentation.observation_growth", exact(s.observation_growth)},
  };
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
