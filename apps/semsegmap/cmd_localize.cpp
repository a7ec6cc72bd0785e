// semsegmap localize: localizes a run against a saved target map; writes localizations.csv,
// matches.csv and trajectory.csv (for semsegmap view), summary.json and a bird's-eye picture.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cli_args.h"
#include "dataset_args.h"
#include "interrupt.h"
#include "localize_follow.h"
#include "progress.h"
#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/diagnostics.h"
#include "semsegmap/eval/localization_picture.h"
#include "semsegmap/outputs/localization_details.h"
#include "semsegmap/outputs/run_output.h"
#include "semsegmap/pipeline/map_parameters.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/settings/config.h"
#include "semsegmap/store/map_location.h"
#include "semsegmap/store/map_store_uri.h"
#include "semsegmap/store/store_tiles.h"

namespace semsegmap::app {

namespace {

// One line: counts, errors (only what ground truth measured: no "0 within 1 m" without it) and
// speed.
void printLocalizationSummary(const LocalizationRun& run) {
  const LocalizationSummary s = summarize(run);
  std::printf("frames %zu  localizations %zu", run.stats.frames, s.localizations);
  if (s.below_1m && s.below_5m)
    std::printf("  <1 m %zu  <5 m %zu", *s.below_1m, *s.below_5m);
  else if (s.localizations > 0 && s.with_ground_truth > 0)
    std::printf("  (%zu with ground truth)", s.with_ground_truth);
  if (s.mean_translation_error_m && s.mean_rotation_error_deg)
    std::printf("  mean error %.2f m %.2f deg", *s.mean_translation_error_m,
                *s.mean_rotation_error_deg);
  if (run.trajectory_gt.empty()) std::printf("  (no ground truth: errors unknown)");
  std::printf("  %.1f Hz", run.stats.fps());
  // Errors against the poses the local map was built on say little: marked.
  if (run.odometry_is_ground_truth && s.mean_translation_error_m)
    std::printf("  [errors against the ground truth used as odometry]");
  std::printf("\n");
  if (run.stats.labelling) printLabelling(*run.stats.labelling);
}

// --prior X,Y[,RADIUS]: where the robot is known to be, in the map frame (radius 50 m).
std::optional<RelocalizationPrior> priorOf(const CliArgs& a, const PipelineConfig& config) {
  if (!a.has("prior")) return std::nullopt;
  if (!config.localization.relocalization.enabled)
    throw UsageError("--prior narrows a relocalization: give --relocalize too");
  std::vector<double> v;
  std::stringstream text(a.get("prior"));
  for (std::string item; std::getline(text, item, ',');) {
    char* end = nullptr;
    v.push_back(std::strtod(item.c_str(), &end));
    if (item.empty() || *end != '\0' || !std::isfinite(v.back()))
      throw UsageError("--prior: expected X,Y or X,Y,RADIUS in metres, got " + a.get("prior"));
  }
  if (v.size() < 2 || v.size() > 3 || (v.size() == 3 && v[2] <= 0))
    throw UsageError("--prior: expected X,Y or X,Y,RADIUS (RADIUS > 0), got " + a.get("prior"));
  RelocalizationPrior prior;
  prior.position = Eigen::Vector3d(v[0], v[1], 0.0);
  if (v.size() == 3) prior.radius_m = v[2];
  return prior;
}

void writeLocalizeFiles(const CliArgs& a, const LocalizationRun& run, const TargetMap& map,
                        const std::string& dataset);
void printWritten(const CliArgs& a);

// The tiles of a store map whose URI has region=X,Y,RADIUS (docs/map-store.md), centred there;
// nothing for a file or a whole store map.
std::shared_ptr<StoreTiles> storeTiles(const std::string& where) {
  if (!isMapStoreUri(where)) return nullptr;
  requireMapStoreBuilt(where);
  const MapStoreUri uri = parseMapStoreUri(where);
  if (!uri.region) return nullptr;
#if SEMSEGMAP_WITH_POSTGRES
  return std::make_shared<StoreTiles>(uri, Eigen::Vector2d(uri.region->x, uri.region->y),
                                      uri.region->radius_m);
#else
  return nullptr;
#endif
}

int runLocalize(const CliArgs& a) {
  if (a.has("follow") && a.get("dataset").rfind("folder:", 0) != 0)
    throw UsageError("--follow follows a folder a driver writes into: give --dataset folder:DIR");
  if (a.has("follow-idle") && !a.has("follow"))
    throw UsageError("--follow-idle says when --follow stops: give --follow too");
  if (a.has("follow-idle") && !(a.getNumber("follow-idle") > 0))
    throw UsageError("--follow-idle: expected a positive number of seconds, got " +
                     a.get("follow-idle"));
  PipelineConfig config = loadPipelineConfig(a.get("config"));
  if (a.has("relocalize")) config.localization.relocalization.enabled = true;
  const std::optional<RelocalizationPrior> prior = priorOf(a, config);
  const std::filesystem::path map_path = a.get("map");
  const std::filesystem::path out = a.get("out");
  // A store map with region=: its tiles around the region, more as the robot moves.
  std::shared_ptr<StoreTiles> tiles = storeTiles(map_path.string());
  const auto map = std::make_shared<const TargetMap>(
      tiles ? tiles->around(tiles->centre().x(), tiles->centre().y())
            : loadMapAt(map_path.string()));
  // The map's recorded build settings against the configuration's, before the data is opened;
  // with --allow-config-mismatch the session warns of each difference instead.
  const MapSettingsCheck settings =
      a.has("allow-config-mismatch") ? MapSettingsCheck::kWarn : MapSettingsCheck::kRefuse;
  if (settings == MapSettingsCheck::kRefuse)
    checkMapParameters(map_path.string(), *map, config, settings,
                       "rebuild the map with this configuration, or give --allow-config-mismatch");
  // The kind before the data; the model, which may follow from the data's modalities
  // (chooseDescriptor), is compared once the describer is made, still before any frame.
  const std::string kind = descriptorName(parseDescriptorKind(config.descriptor.kind));
  if (map->descriptor != kind)
    throw std::runtime_error(map_path.string() + ": map built with " + map->descriptor +
                             " descriptors, the configuration uses " + kind);
  requireDescriberBuilt(config.descriptor);  // a part this build lacks, before the data
  if (a.has("follow")) {
    FollowedRun followed = followFolder(a, config, map, settings, prior, tiles);
    writeLocalizeFiles(a, followed.run, *map, followed.dataset);
    printLocalizationSummary(followed.run);
    printWritten(a);
    return 0;
  }
  // The network and LiDAR odometry, when asked for, run inside the pipeline.
  DatasetWithStages data = openDatasetForPipelineArg(a);
  std::unique_ptr<FrameSource>& source = data.source;
  std::shared_ptr<Describer> describer = describerFor(config.descriptor, *source);
  checkMapCompatible(map_path, *map, descriptorName(describer->kind()), describer->fingerprint(),
                     describer->dimension());

  Progress progress("localize", 0);
  RunOptions options;
  options.max_frames = a.frameLimit();
  options.progress = [&](size_t done, size_t total) { progress.update(done, total); };
  options.stop = stopToken();
  options.stages = data.stages;
  const LocalizationRun run =
      runLocalization(*source, config, map, describer, options, settings, prior, tiles);
  if (tiles) note("map tiles: " + std::to_string(tiles->tilesLoaded()) + " loaded along the drive");
  // Stopped before its first frame: nothing worth writing (main removes what the run made).
  if (run.stats.interrupted && run.stats.frames == 0)
    return interruptedRun("localize", 0, options.frameCount(*source), out.string());
  writeLocalizeFiles(a, run, *map, source->info().name);
  printLocalizationSummary(run);
  printWritten(a);
  if (run.stats.interrupted)
    return interruptedRun("localize", run.stats.frames, options.frameCount(*source), out.string());
  return 0;
}

// localizations.csv, matches.csv, trajectory.csv, localization.png and, last (a summary says the
// run completed), summary.json.
void writeLocalizeFiles(const CliArgs& a, const LocalizationRun& run, const TargetMap& map,
                        const std::string& dataset) {
  const std::filesystem::path map_path = a.get("map");
  const std::filesystem::path out = a.get("out");
  writeLocalizationsCsv(out / "localizations.csv", run);
  writeLocalizationDetails(out, run);  // matches.csv, trajectory.csv: for semsegmap view
  writeLocalizationPicture(out / "localization.png", run, map,
                           dataset + " against " + mapDisplayName(map_path.string()) + " (" +
                               std::filesystem::path(a.get("config")).stem().string() + ")");
  SummaryContext context;
  context.dataset = dataset;
  // A store's map: its URI without the password, and no file size.
  const bool stored = isMapStoreUri(map_path.string());
  context.map = stored ? map.source : map_path.string();
  context.config = a.get("config");
  context.descriptor = map.descriptor;
  context.map_segments = map.size();
  context.map_bytes = stored ? 0 : std::filesystem::file_size(map_path);
  writeBytesAtomically(out / "summary.json", localizationSummaryJson(run, context));
}

void printWritten(const CliArgs& a) {
  std::cout << "wrote " << (std::filesystem::path(a.get("out")) / "localizations.csv").string()
            << ", matches.csv, trajectory.csv, summary.json, localization.png\n";
}

}  // namespace

const CommandSpec& localizeCommand() {
  static const CommandSpec command{
      "localize",
      "localizes a run against a target map -> localizations.csv, summary.json, .png",
      datasetOptions(
          "the run to localize",
          {
              {"config", Value::kText, "FILE", "",
               "pipeline configuration, the one the map was built with", kRequired},
              {"map", Value::kText, "MAP", "",
               "the target map (semsegmap map): a file, or postgresql://...?map=NAME"
               "[&region=X,Y,RADIUS] (docs/map-store.md)",
               kRequired},
              {"out", Value::kText, "DIR", "", "output folder", kRequired},
              maxFramesOption(),
              {"allow-config-mismatch", Value::kFlag, "", "",
               "localize even when the map was built with other settings (listed on stderr)"},
              {"relocalize", Value::kFlag, "", "",
               "search the whole map when not localized for a while (localization.relocalization, "
               "on in config/lidar-camera.yaml; a map without its points localizes without it)"},
              {"prior", Value::kText, "X,Y[,RADIUS]", "",
               "relocalize only within RADIUS m (default 50) of X,Y in the map frame"},
              {"follow", Value::kFlag, "", "",
               "follow a folder: dataset as a driver writes into it, printing each pose as it "
               "is found (LiDAR odometry on its scans; files taken once renamed into place)"},
              {"follow-idle", Value::kText, "SECONDS", "",
               "with --follow: stop after this long without a new scan (default: at Ctrl-C)"},
          }),
      kDatasetNotes,
      runLocalize,
      /*stops_between_frames=*/true};
  return command;
}

}  // namespace semsegmap::app
