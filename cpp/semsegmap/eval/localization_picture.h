// The bird's-eye picture of a localization run (viz/localization_png.h) from the run and its
// target map: every localization coloured by its error, and the matches of the localization
// with the most inliers drawn as lines.
#pragma once

#include <filesystem>
#include <string>

#include "semsegmap/pipeline/modes.h"

namespace semsegmap {

void writeLocalizationPicture(const std::filesystem::path& png, const LocalizationRun& run,
                              const TargetMap& map, const std::string& title);

}  // namespace semsegmap
