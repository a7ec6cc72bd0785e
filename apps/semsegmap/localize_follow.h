// semsegmap localize --follow: a folder a driver is writing into, localized as it grows (a robot
// without ROS). The files go through the live session (pipeline/live_session.h) as they appear;
// each pose is printed when found; the run's files are written when it ends (no new scan for
// --follow-idle seconds, or Ctrl-C).
#pragma once

#include <memory>
#include <optional>

#include "cli_args.h"
#include "semsegmap/localize/target_map.h"
#include "semsegmap/pipeline/map_parameters.h"
#include "semsegmap/pipeline/modes.h"

namespace semsegmap::app {

// The run, for runLocalize to write its files as for a recording.
struct FollowedRun {
  LocalizationRun run;
  std::string dataset;  // the folder's name
};

// `tiles`: a store map served in tiles (pipeline/map_tiles.h), followed as the robot moves; or
// nothing.
FollowedRun followFolder(const CliArgs& a, const PipelineConfig& config,
                         std::shared_ptr<const TargetMap> map, MapSettingsCheck settings,
                         const std::optional<RelocalizationPrior>& prior,
                         std::shared_ptr<MapTileSource> tiles = nullptr);

}  // namespace semsegmap::app
