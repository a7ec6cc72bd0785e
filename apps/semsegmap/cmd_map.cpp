// semsegmap map: runs the pipeline over a mapping run and saves the target map.
#include <ctime>
#include <filesystem>
#include <iostream>
#include <set>

#include "cli_args.h"
#include "dataset_args.h"
#include "interrupt.h"
#include "progress.h"
#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/pipeline/session_merge.h"
#include "semsegmap/pipeline/slam.h"
#include "semsegmap/settings/config.h"
#include "semsegmap/store/map_location.h"
#include "semsegmap/store/map_store_uri.h"
#include "semsegmap/store/pg_map_store.h"  // its types; its functions only WITH_POSTGRES

namespace semsegmap::app {

namespace {

// Where a session that did not join the map goes instead of `out`: beside it, never over it (a
// file beside the file; in a store, a map of its own named after the map and the time).
std::string separateLocation(const std::string& out, int64_t now_unix_s) {
  if (isMapStoreUri(out)) {
    const MapStoreUri uri = parseMapStoreUri(out);
    return uri.conninfo + (uri.conninfo.find('?') == std::string::npos ? "?" : "&") +
           "map=" + uri.map + ".unaligned." + std::to_string(now_unix_s);
  }
  std::filesystem::path p = out;
  p.replace_extension(".unaligned" + p.extension().string());
  return p.string();
}

// The map a session joins, and what it was when loaded: a store's map is read whole (the session
// may have driven anywhere in it).
TargetMap loadMapToJoin(const std::string& into, MapSnapshot& snapshot) {
  if (isMapStoreUri(into) && parseMapStoreUri(into).region)
    throw UsageError("--into " + shownLocation(into) +
                     ": a session joins the whole map, drop region=");
  return loadMapAt(into, &snapshot);
}

// The merged map's new session, written in place into the store map it joined (one
// transaction), or the whole merged map to `out`.
void writeJoined(const std::string& into, const std::string& out, const MergedSession& m,
                 const MapSnapshot& snapshot, const PipelineConfig& config,
                 const MapWriteOptions& write, const std::string& session_name) {
#if SEMSEGMAP_WITH_POSTGRES
  if (isMapStoreUri(into) && out == into) {
    const MapStoreUri uri = parseMapStoreUri(into);
    PgMapStore store(uri);
    const SessionWrite w = store.addSession(uri.map, lastSessionOf(m.map, snapshot), snapshot,
                                            config.session_merge.same_segment_m);
    std::printf(
        "session %lld written into %s: %zu entries, %zu new segments, %zu joined to "
        "sessions written meanwhile\n",
        static_cast<long long>(w.session), uri.shown.c_str(), w.entries, w.new_segments,
        w.joined_meanwhile);
    return;
  }
#else
  (void)into, (void)snapshot, (void)config;
#endif
  const uint64_t bytes = saveMapAt(out, m.map, write, session_name);
  if (bytes) std::printf("%llu bytes\n", static_cast<unsigned long long>(bytes));
}

// `map --into MAP`: the run joins MAP as a new session (pipeline/session_merge.h).
int runMapInto(const CliArgs& a, const PipelineConfig& config, DatasetWithStages& data,
               std::shared_ptr<Describer> describer, PoseSource poses, RunOptions options) {
  const std::string into = a.get("into"), out = a.get("out");
  MapSnapshot snapshot;
  auto map = std::make_shared<const TargetMap>(loadMapToJoin(into, snapshot));
  Progress progress("map", 0);
  options.progress = [&](size_t done, size_t total) { progress.update(done, total); };
  const auto now = static_cast<int64_t>(std::time(nullptr));
  const MergedSession m = runSessionMerge(*data.source, config, map, std::move(describer),
                                          a.get("dataset"), now, poses, options);
  MapWriteOptions write;
  write.float16 = !a.has("float32");
  if (!m.aligned) {
    const std::string separate = separateLocation(out, now);
    saveMapAt(separate, m.map, write, a.get("dataset"));
    std::cerr << "semsegmap map: " << a.get("dataset") << " localized " << m.ties.size()
              << " times against " << mapDisplayName(into) << " ("
              << config.session_merge.min_localizations
              << " needed): not merged; its own map, in its own frame, written to "
              << shownLocation(separate) << "\n";
    return 3;
  }
  std::set<uint32_t> segments;
  for (const MapSegment& s : m.map.segments) segments.insert(s.segment);
  std::printf(
      "frames %zu  localized %zu against %s (mean residual %.2f m after the pose graph)  "
      "session entries %zu, %zu of them observations of segments the map held\n"
      "map %zu sessions, %zu entries of %zu segments\n",
      m.mapping.stats.frames, m.ties.size(), mapDisplayName(into).c_str(), m.mean_tie_residual_m,
      m.entries, m.same_segments, m.map.sessions.size(), m.map.size(), segments.size());
  writeJoined(into, out, m, snapshot, config, write, a.get("dataset"));
  std::cout << "wrote " << shownLocation(out) << "\n";
  if (m.mapping.stats.interrupted)
    return interruptedRun("map", m.mapping.stats.frames, options.frameCount(*data.source), out);
  return 0;
}

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
  const std::string out = a.get("out");
  requireMapStoreBuilt(out);  // before hours of mapping
  if (a.has("into")) requireMapStoreBuilt(a.get("into"));
  requireDescriberBuilt(config.descriptor);  // a part this build lacks, before the data
  // The network and LiDAR odometry, when asked for, run inside the pipeline.
  DatasetWithStages data = openDatasetForPipelineArg(a);
  std::unique_ptr<FrameSource>& source = data.source;
  // The model before any frame: a missing one, or a descriptor this build has not, fails first.
  std::shared_ptr<Describer> describer = describerFor(config.descriptor, *source);
  const std::string poses = a.has("poses")                          ? a.get("poses")
                            : source->info().has_ground_truth_poses ? "gt"
                                                                    : "odom";

  RunOptions options;
  options.max_frames = a.frameLimit();
  // The map of the frames done is whole and usable: saved as any other.
  options.stop = stopToken();
  options.stages = data.stages;
  if (a.has("into")) {
    if (poses == "slam")
      throw UsageError(
          "--into joins a run by localizing it against the map: use --poses odom "
          "or gt, not slam");
    return runMapInto(a, config, data, describer, parsePoseSource(poses), options);
  }
  Progress progress("map", 0);
  options.progress = [&](size_t done, size_t total) { progress.update(done, total); };
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
    return interruptedRun("map", 0, options.frameCount(*source), out);
  MapWriteOptions write;
  write.float16 = !a.has("float32");
  const uint64_t bytes = saveMapAt(out, map, write, a.get("dataset"));
  const std::string kept =
      earlier ? " + " + std::to_string(earlier) + " earlier observations of them" : "";
  char size[96] = "in the store";  // a store's size is the server's business
  if (!isMapStoreUri(out))
    std::snprintf(size, sizeof size, "%llu bytes (%.1f bytes/segment)",
                  static_cast<unsigned long long>(bytes),
                  map.size() ? static_cast<double>(bytes) / map.size() : 0.0);
  std::printf(
      "frames %zu  segments %zu%s (%zu duplicates removed)  map %zu segments, %s  "
      "pipeline %.1f Hz\n",
      stats.frames, segments, kept.c_str(), duplicates, map.size(), size, stats.fps());
  if (stats.labelling) printLabelling(*stats.labelling);
  std::cout << "wrote " << shownLocation(out) << "\n";
  if (stats.interrupted)
    return interruptedRun("map", stats.frames, options.frameCount(*source), out);
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
              {"out", Value::kText, "MAP", "",
               "the map to write: a file, or postgresql://...?map=NAME, a new map in a store "
               "(docs/map-store.md)",
               kRequired},
              {"into", Value::kText, "MAP", "",
               "join the run to this map as a new session (docs/map-store.md); --out gets "
               "the merged map (--out the same store map as --into: the session is added in "
               "place, in one transaction)"},
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
