// semsegmap map: runs the pipeline over a mapping run and saves the target map.
#include <filesystem>
#include <iostream>

#include "cli_args.h"
#include "dataset_args.h"
#include "interrupt.h"
#include "progress.h"
#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/pipeline/slam.h"
#include "semsegmap/settings/config.h"

namespace semsegmap::app {

namespace {

int runMap(const CliArgs& a) {
  PipelineConfig config = loadPipelineConfig(a.get("config"));
  // Without --points the configuration's target_map.max_points_per_segment holds: a config that
  // refines poses builds maps its localization can use.
  if (a.has("points")) {
    const size_t points = a.getCount("points");
    if (points > 65535)
      throw UsageError("option --points must be in 0..65535, got " + a.get("points"));
    config.target_map.max_points_per_segment = points;
  }
  const std::filesystem::path out = a.get("out");
  requireDescriberBuilt(config.descriptor);  // a part this build lacks, before the data
  // The network and LiDAR odometry, when asked for, run inside the pipeline.
  DatasetWithStages data = openDatasetForPipelineArg(a);
  std::unique_ptr<FrameSource>& source = data.source;
  // The model before any frame: a missing one, or a descriptor this build has not, fails first.
  std::shared_ptr<Describer> describer = describerFor(config.descriptor, *source);
  const std::string poses = a.has("poses")                          ? a.get("poses")
                            : source->info().has_ground_truth_poses ? "gt"
                                                                    : "odom";

  Progress progress("map", 0);
  RunOptions options;
  options.max_frames = a.frameLimit();
  options.progress = [&](size_t done, size_t total) { progress.update(done, total); };
  // The map of the frames done is whole and usable: saved as any other.
  options.stop = stopToken();
  options.stages = data.stages;
  TargetMap map;
  RunStats stats;
  size_t segments = 0, earlier = 0, duplicates = 0;
  if (poses == "slam") {
    SlamRun run = runSlam(*source, config, describer, options);
    map = std::move(run.map);
    stats = run.stats;
    segments = map.size();
  } else {
    MappingRun run = runMapping(*source, config, parsePoseSource(poses), describer, options);
    map = std::move(run.map);
    stats = run.stats;
    segments = run.segments;
    earlier = run.earlier_observations;
    duplicates = run.duplicates_removed;
  }
  // Stopped before its first frame: no map of nothing.
  if (stats.interrupted && stats.frames == 0)
    return interruptedRun("map", 0, options.frameCount(*source), out.string());
  MapWriteOptions write;
  write.float16 = !a.has("float32");
  const uint64_t bytes = saveTargetMap(out, map, write);
  const std::string kept =
      earlier ? " + " + std::to_string(earlier) + " earlier observations of them" : "";
  std::printf(
      "frames %zu  segments %zu%s (%zu duplicates removed)  map %zu segments, %llu bytes "
      "(%.1f bytes/segment)  pipeline %.1f Hz\n",
      stats.frames, segments, kept.c_str(), duplicates, map.size(),
      static_cast<unsigned long long>(bytes),
      map.size() ? static_cast<double>(bytes) / map.size() : 0.0, stats.fps());
  if (stats.labelling) printLabelling(*stats.labelling);
  std::cout << "wrote " << out.string() << "\n";
  if (stats.interrupted)
    return interruptedRun("map", stats.frames, options.frameCount(*source), out.string());
  return 0;
}

}  // namespace

const CommandSpec& mapCommand() {
  static const CommandSpec command{
      "map",
      "builds a target map from a mapping run and saves it (docs/map-format.md)",
      datasetOptions(
          "the mapping run",
          {
              {"config", Value::kText, "FILE", "", "pipeline configuration, config/*.yaml",
               kRequired},
              {"out", Value::kText, "MAP", "", "the map file to write", kRequired},
              {"poses", Value::kText, "gt|odom|slam", "",
               "poses the map is built with (default: gt when the data has them, else odom)"},
              maxFramesOption(),
              {"points", Value::kCount, "N", "",
               "points kept per segment, for pictures and pose refinement "
               "(localization.refinement), 0..65535 "
               "(default: the config's target_map.max_points_per_segment)"},
              {"float32", Value::kFlag, "", "", "store descriptors as float32 instead of float16"},
          }),
      kDatasetNotes,
      runMap,
      /*stops_between_frames=*/true};
  return command;
}

}  // namespace semsegmap::app
