// The settings of a configuration that a target map's segments depend on, recorded in the map
// (io/map_file.h) and compared before localizing against it: enrichment, local map and
// segmentation, by their YAML keys. The descriptor's kind, dimension and model are in the map's
// header already (checkMapCompatible); batch sizes and picture points change no segment.
#pragma once

#include "semsegmap/localize/target_map.h"
#include "semsegmap/pipeline/pipeline_config.h"

namespace semsegmap {

MapParameters mapParametersOf(const PipelineConfig& config);

}  // namespace semsegmap
