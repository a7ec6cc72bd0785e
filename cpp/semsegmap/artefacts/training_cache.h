// The cache of extracted training observations (learn/training_data.h).
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "semsegmap/learn/training_data.h"

namespace semsegmap {

// The cache of extracted observations, so that a second training run does not re-run the
// simulator. `provenance` says what the data was made from (specs, configuration); read returns
// nullopt when the file is missing or was made from something else, and throws naming the file
// when it is truncated or corrupt. Written to a temporary name and renamed.
void writeTrainingCache(const std::filesystem::path& path, const TrainingSet& set,
                        const std::string& provenance);
std::optional<TrainingSet> readTrainingCache(const std::filesystem::path& path,
                                             const std::string& provenance);

}  // namespace semsegmap
