// The settings of a configuration that a target map's segments depend on, recorded in the map
// (artefacts/map_file.h) and compared before localizing against it: enrichment, local map and
// segmentation: the settings the setting table marks recorded (pipeline/setting_table.h), by
// their keys. The descriptor's kind, dimension and model are in the map's
// header already (checkMapCompatible); batch sizes and picture points change no segment.
#pragma once

#include "semsegmap/localize/target_map.h"
#include "semsegmap/pipeline/pipeline_config.h"

namespace semsegmap {

MapParameters mapParametersOf(const PipelineConfig& config);

// A map's recorded settings as this build records them: old keys by their names now (the setting
// table's aliases), keys that older builds did not write added with the value that their rules
// implied. Applied before every comparison.
MapParameters upgradeMapParameters(MapParameters recorded);

// What a difference between a map's recorded settings and the configuration's does: refuse (a
// map grown with another voxel size or growing radius holds segments the run never makes, and
// localized nothing with exit 0), or go on with a warning for each difference.
enum class MapSettingsCheck { kRefuse, kWarn };

// Throws std::runtime_error naming `map_name`, the first differing key and both values, and
// `remedy`; with kWarn, warns (core/diagnostics.h) once per difference. A map that records no
// settings (made by hand, not by MappingSession) has nothing to compare and passes.
void checkMapParameters(const std::string& map_name, const TargetMap& map,
                        const PipelineConfig& config, MapSettingsCheck check,
                        const std::string& remedy = "rebuild the map with this configuration");

}  // namespace semsegmap
