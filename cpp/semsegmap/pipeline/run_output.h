// The files a localization run leaves behind: one CSV row per localization and a JSON summary
// that evaluations across commits can compare.
#pragma once

#include <filesystem>
#include <string>

#include "semsegmap/pipeline/modes.h"

namespace semsegmap {

// frame, timestamp, T_map_robot as x y z qx qy qz qw, inliers, and with ground truth the
// translation error in m and the rotation error in degrees.
void writeLocalizationsCsv(const std::filesystem::path& path, const LocalizationRun& run);

struct SummaryContext {
  std::string dataset, map, config, descriptor;
  size_t map_segments = 0;
  uint64_t map_bytes = 0;
};
std::string localizationSummaryJson(const LocalizationRun& run, const SummaryContext& context);

}  // namespace semsegmap
