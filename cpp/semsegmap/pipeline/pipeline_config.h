// The configuration of the whole pipeline: one struct per stage, each with its defaults next to
// the code that uses it. io/config.h reads it from YAML.
#pragma once

#include "semsegmap/enrich/enricher.h"
#include "semsegmap/local_map/local_map.h"
#include "semsegmap/segment/semantic_distance.h"

namespace semsegmap {

struct PipelineConfig {
  EnrichmentConfig enrichment;
  LocalMapConfig local_map;
  SegmentationConfig segmentation;
};

}  // namespace semsegmap
