// semsegmap map: runs the pipeline over a mapping run and saves the target map.
#include <filesystem>
#include <iostream>

#include "cli_args.h"
#include "progress.h"
#include "semsegmap/io/config.h"
#include "semsegmap/io/open_dataset.h"
#include "semsegmap/localize/map_file.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/pipeline/slam.h"

namespace semsegmap::app {

int runMap(const std::vector<std::string>& args) {
  const CliArgs a(args, {"dataset", "config", "out", "poses", "max-frames", "points"}, {"float32"});
  PipelineConfig config = loadPipelineConfig(a.require("config"));
  const std::filesystem::path out = a.require("out");
  auto source = openDataset(a.require("dataset"));
  const std::string poses = a.get("poses", source->info().has_ground_truth_poses ? "gt" : "odom");
  const long long max_frames = a.getInt("max-frames", 0);
  if (max_frames < 0) throw std::invalid_argument("--max-frames must not be negative");
  const long long points = a.getInt("points", 0);
  if (points < 0 || points > 65535) throw std::invalid_argument("--points must be in 0..65535");
  config.target_map.max_points_per_segment = static_cast<size_t>(points);
  auto describer = makeDescriber(config.descriptor);

  Progress progress("map", 0);
  RunOptions options;
  options.max_frames = static_cast<size_t>(max_frames);
  options.progress = [&](size_t done, size_t total) { progress.update(done, total); };
  TargetMap map;
  RunStats stats;
  size_t segments = 0, duplicates = 0;
  if (poses == "slam") {
    SlamRun run = runSlam(*source, config, *describer, options);
    map = std::move(run.map);
    stats = run.stats;
    segments = map.size();
  } else {
    MappingRun run = runMapping(*source, config, parsePoseSource(poses), *describer, options);
    map = std::move(run.map);
    stats = run.stats;
    segments = run.segments;
    duplicates = run.duplicates_removed;
  }
  if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
  MapWriteOptions write;
  write.float16 = !a.has("float32");
  const uint64_t bytes = saveTargetMap(out, map, write);
  std::printf(
      "frames %zu  segments %zu (%zu duplicates removed)  map %zu segments, %llu bytes "
      "(%.1f bytes/segment)  pipeline %.1f Hz\n",
      stats.frames, segments, duplicates, map.size(), static_cast<unsigned long long>(bytes),
      map.size() ? static_cast<double>(bytes) / map.size() : 0.0, stats.fps());
  std::cout << "wrote " << out.string() << "\n";
  return 0;
}

}  // namespace semsegmap::app
