// semsegmap localize: localizes a run against a saved target map; writes localizations.csv,
// summary.json and a bird's-eye picture.
#include <filesystem>
#include <iostream>

#include "cli_args.h"
#include "progress.h"
#include "semsegmap/eval/localization_picture.h"
#include "semsegmap/io/atomic_file.h"
#include "semsegmap/io/config.h"
#include "semsegmap/io/open_dataset.h"
#include "semsegmap/localize/map_file.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/pipeline/run_output.h"

namespace semsegmap::app {

int runLocalize(const std::vector<std::string>& args) {
  const CliArgs a(args, {"dataset", "config", "map", "out", "max-frames"}, {});
  const PipelineConfig config = loadPipelineConfig(a.require("config"));
  const std::filesystem::path map_path = a.require("map");
  const std::filesystem::path out = a.require("out");
  const TargetMap map = loadTargetMap(map_path);
  auto describer = makeDescriber(config.descriptor);
  checkMapCompatible(map_path, map, descriptorName(describer->kind()), describer->fingerprint(),
                     describer->dimension());
  auto source = openDataset(a.require("dataset"));
  const long long max_frames = a.getInt("max-frames", 0);
  if (max_frames < 0) throw std::invalid_argument("--max-frames must not be negative");
  std::filesystem::create_directories(out);

  Progress progress("localize", 0);
  RunOptions options;
  options.max_frames = static_cast<size_t>(max_frames);
  options.progress = [&](size_t done, size_t total) { progress.update(done, total); };
  const LocalizationRun run = runLocalization(*source, config, map, *describer, options);

  writeLocalizationsCsv(out / "localizations.csv", run);
  SummaryContext context;
  context.dataset = source->info().name;
  context.map = map_path.string();
  context.config = a.require("config");
  context.descriptor = map.descriptor;
  context.map_segments = map.size();
  context.map_bytes = std::filesystem::file_size(map_path);
  writeBytesAtomically(out / "summary.json", localizationSummaryJson(run, context));
  writeLocalizationPicture(out / "localization.png", run, map,
                           source->info().name + " against " + map_path.filename().string() + " (" +
                               std::filesystem::path(a.require("config")).stem().string() + ")");

  const LocalizationSummary s = summarize(run.localizations);
  if (run.trajectory_gt.empty())  // errors need ground truth; zeros would read as perfect
    std::printf("frames %zu  localizations %zu  (no ground truth: errors unknown)  %.1f Hz\n",
                run.stats.frames, s.localizations, run.stats.fps());
  else
    std::printf(
        "frames %zu  localizations %zu  <1 m %zu  <5 m %zu  mean error %.2f m %.2f deg  "
        "%.1f Hz\n",
        run.stats.frames, s.localizations, s.below_1m, s.below_5m, s.mean_translation_error_m,
        s.mean_rotation_error_deg, run.stats.fps());
  std::cout << "wrote " << (out / "localizations.csv").string()
            << ", summary.json, localization.png\n";
  return 0;
}

}  // namespace semsegmap::app
