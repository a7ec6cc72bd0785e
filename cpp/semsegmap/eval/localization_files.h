// What the localization experiments leave behind, shared by the paper's (localization_experiment.h)
// and the revisit check (revisit_experiment.h): the target maps they build and save, and each
// localization run's files.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "semsegmap/eval/experiment.h"
#include "semsegmap/localize/target_map.h"
#include "semsegmap/outputs/run_output.h"
#include "semsegmap/pipeline/modes.h"

namespace semsegmap {

// A configuration's target map as an experiment built it (with the points its pictures need) and
// the size of the file saved for it.
struct BuiltMap {
  std::shared_ptr<const TargetMap> map;
  uint64_t bytes = 0;
};

// One mapping session per configuration on ground-truth poses, each keeping at least
// `picture_points` points a segment (more when its configuration asks: pose refinement).
std::vector<std::unique_ptr<MappingSession>> mappingSessions(
    const std::vector<NamedConfig>& configs, const DatasetInfo& info,
    const std::vector<std::shared_ptr<Describer>>& describers, size_t picture_points);

// out/maps/<config>.map: where an experiment saves a configuration's map.
std::filesystem::path builtMapPath(const std::filesystem::path& out, const NamedConfig& config);

// Finishes every session and saves its map to builtMapPath (saveBuiltMap).
std::vector<BuiltMap> finishMaps(std::vector<std::unique_ptr<MappingSession>>& sessions,
                                 const std::vector<NamedConfig>& configs,
                                 const std::filesystem::path& out);

// Saves `built` to `path` as a robot would carry it: with the `kept_points` points a segment its
// configuration keeps (target_map.max_points_per_segment, 0: none), not the pictures'.
BuiltMap saveBuiltMap(const std::filesystem::path& path, TargetMap built, size_t kept_points);

// localizations.csv, matches.csv, trajectory.csv (outputs/localization_details.h), summary.json and
// localization.png of one run in `dir`; the map's descriptor, size and bytes are filled into
// `context`.
void writeLocalizationRunFiles(const std::filesystem::path& dir, const LocalizationRun& run,
                               const BuiltMap& map, SummaryContext context,
                               const std::string& title);

}  // namespace semsegmap
