#include "semsegmap/eval/localization_files.h"

#include <algorithm>

#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/eval/localization_picture.h"
#include "semsegmap/outputs/localization_details.h"

namespace semsegmap {

std::vector<std::unique_ptr<MappingSession>> mappingSessions(
    const std::vector<NamedConfig>& configs, const DatasetInfo& info,
    const std::vector<std::shared_ptr<Describer>>& describers, size_t picture_points) {
  std::vector<std::unique_ptr<MappingSession>> sessions;
  for (size_t c = 0; c < configs.size(); ++c) {
    PipelineConfig pc = configs[c].config;
    pc.target_map.max_points_per_segment =
        std::max(pc.target_map.max_points_per_segment, picture_points);
    sessions.push_back(
        std::make_unique<MappingSession>(pc, info, PoseSource::kGroundTruth, describers[c]));
  }
  return sessions;
}

std::filesystem::path builtMapPath(const std::filesystem::path& out, const NamedConfig& config) {
  return out / "maps" / (config.name + ".map");
}

std::vector<BuiltMap> finishMaps(std::vector<std::unique_ptr<MappingSession>>& sessions,
                                 const std::vector<NamedConfig>& configs,
                                 const std::filesystem::path& out) {
  std::vector<BuiltMap> maps;
  for (size_t c = 0; c < configs.size(); ++c)
    maps.push_back(saveBuiltMap(builtMapPath(out, configs[c]), sessions[c]->finish().map,
                                configs[c].config.target_map.max_points_per_segment));
  return maps;
}

BuiltMap saveBuiltMap(const std::filesystem::path& path, TargetMap built, size_t kept_points) {
  BuiltMap m;
  TargetMap saved = built;
  for (MapSegment& s : saved.segments) s.points = subsamplePoints(s.points, kept_points);
  m.bytes = saveTargetMap(path, saved);
  m.map = std::make_shared<const TargetMap>(std::move(built));
  return m;
}

void writeLocalizationRunFiles(const std::filesystem::path& dir, const LocalizationRun& run,
                               const BuiltMap& map, SummaryContext context,
                               const std::string& title) {
  std::filesystem::create_directories(dir);
  writeLocalizationsCsv(dir / "localizations.csv", run);
  writeLocalizationDetails(dir, run);  // matches.csv, trajectory.csv: for semsegmap view
  context.descriptor = map.map->descriptor;
  context.map_segments = map.map->size();
  context.map_bytes = map.bytes;
  writeBytesAtomically(dir / "summary.json", localizationSummaryJson(run, context));
  writeLocalizationPicture(dir / "localization.png", run, *map.map, title);
}

}  // namespace semsegmap
