#include "semsegmap/eval/revisit_experiment.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/frame_subset.h"
#include "semsegmap/eval/ground_truth_check.h"
#include "semsegmap/eval/localization_files.h"
#include "semsegmap/eval/localization_metrics.h"
#include "semsegmap/outputs/run_output.h"
#include "semsegmap/pipeline/input_modalities.h"
#include "semsegmap/viz/plot.h"

namespace semsegmap {

namespace {

std::vector<size_t> framesOf(const std::vector<FrameRange>& ranges) {
  std::vector<size_t> frames;
  for (const FrameRange& r : ranges)
    for (size_t i = r.first; i <= r.last; ++i) frames.push_back(i);
  std::sort(frames.begin(), frames.end());
  frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
  return frames;
}

std::string rangeText(const FrameRange& r) {
  return std::to_string(r.first) + ":" + std::to_string(r.last);
}

// Everything that can be checked before a frame is read.
void checkRevisitInput(const FrameSource& source, const RevisitExperimentConfig& cfg) {
  const std::string name = source.info().name;
  if (cfg.configs.empty())
    throw std::invalid_argument("eval revisits needs at least one configuration");
  for (const NamedConfig& c : cfg.configs)
    if (cfg.scan_context && c.name == kScanContextName)
      throw std::invalid_argument("eval revisits: configuration " + c.path.string() +
                                  " is named like Scan Context's results (" + kScanContextName +
                                  "); rename it, or leave Scan Context out");
  if (!source.info().has_ground_truth_poses)
    throw std::invalid_argument(name +
                                ": eval revisits needs ground-truth poses (--ground-truth FILE)");
  if (!source.info().has_odometry)
    throw std::invalid_argument(
        name + ": the query frames need odometry (--odometry FILE or --odometry lidar)");
  for (const auto* ranges : {&cfg.map_frames, &cfg.query_frames}) {
    if (ranges->empty()) throw std::invalid_argument("eval revisits: no map or no query frames");
    for (const FrameRange& r : *ranges)
      if (r.last >= source.size())
        throw std::invalid_argument(name + ": frames " + rangeText(r) + " are beyond its " +
                                    std::to_string(source.size()) +
                                    " frames (0:" + std::to_string(source.size() - 1) + ")");
  }
  const std::vector<size_t> mapped = framesOf(cfg.map_frames), queried = framesOf(cfg.query_frames);
  std::vector<size_t> both;
  std::set_intersection(mapped.begin(), mapped.end(), queried.begin(), queried.end(),
                        std::back_inserter(both));
  if (!both.empty())
    throw std::invalid_argument("eval revisits: frame " + std::to_string(both.front()) +
                                " is both mapped and queried; the ranges must not overlap");
  size_t listed = 0;
  for (const FrameRange& r : cfg.query_frames) listed += r.last - r.first + 1;
  if (cfg.wake_up_frames > 0 && listed != queried.size())
    throw std::invalid_argument(
        "eval revisits: with wake-ups the query ranges must not overlap each other");
}

// What the map frames leave besides the segment maps: their ground-truth positions, and their
// scans for the ground-truth check and for Scan Context (each when asked for).
struct MappedScans {
  std::vector<Eigen::Vector3d> positions;
  std::optional<GroundTruthCheck> check;
  std::optional<ScanContextLocalizer> scan_context;
};

// The map frames, read once for every configuration, on ground-truth poses.
std::vector<BuiltMap> buildMaps(FrameSource& source, RevisitExperiment& e,
                                const std::vector<std::shared_ptr<Describer>>& describers,
                                const std::filesystem::path& out, MappedScans& mapped,
                                const ExperimentProgress& progress) {
  const RevisitExperimentConfig& cfg = e.config;
  FrameSubset frames(source, framesOf(cfg.map_frames));
  auto sessions =
      mappingSessions(cfg.configs, source.info(), describers, cfg.picture_points_per_segment);
  e.interrupted = !forEachFrame(frames, "map", progress, cfg.stop, [&](const Frame& frame) {
    if (!frame.T_world_base)
      throw std::runtime_error(source.info().name + ": frame " +
                               std::to_string(frames.datasetFrame(frame.index)) +
                               " has no ground-truth pose");
    mapped.positions.push_back(frame.T_world_base->translation());
    const Pose T_world_lidar = *frame.T_world_base * source.info().rig.T_base_lidar;
    if (mapped.check) mapped.check->addMapped(frame.points, T_world_lidar);
    if (mapped.scan_context) mapped.scan_context->addMapped(frame.points, T_world_lidar);
    for (auto& s : sessions) s->process(frame);
  });
  return finishMaps(sessions, cfg.configs, out);
}

// The error a wake-up is judged by: against the registered ground truth where the query scan
// registered to the mapped ones (check_ground_truth), as that is the map's own geometry; a
// recorded ground truth can be off by most of correct_m at a revisit (KITTI's second pass lies
// about 0.8 m above the first), which would count a refined localization as a miss.
double judgedError(const RevisitLocalization& l) {
  return l.registered_error_m >= 0 ? l.registered_error_m : l.translation_error_m;
}

// How soon each wake-up was localized; a session's localizations are in frame order.
std::vector<WakeUp> wakeUpsOf(const RevisitExperiment& e,
                              const std::vector<RevisitLocalization>& localizations) {
  std::vector<WakeUp> out;
  if (e.config.wake_up_frames == 0) return out;
  for (const std::vector<FrameRange>& session : querySessions(e.config)) {
    WakeUp w;
    w.frames = session.front();
    const auto q = std::find_if(e.queries.begin(), e.queries.end(),
                                [&](const RevisitFrame& f) { return f.frame == w.frames.first; });
    if (q == e.queries.end()) continue;  // a session the stop request left unread
    w.revisit = q != e.queries.end() && q->revisit;
    for (const RevisitLocalization& l : localizations) {
      if (l.frame < w.frames.first || l.frame > w.frames.last) continue;
      if (judgedError(l) < e.config.correct_m) {
        w.localized = l.frame - w.frames.first + 1;
        break;
      }
      w.wrong_first = w.wrong_first || judgedError(l) > e.config.wrong_m;
    }
    out.push_back(w);
  }
  return out;
}

// A localization against the query scan's registered ground truth (check_ground_truth).
void compareWithRegistered(RevisitResult& r, const LocalizationRecord& l, const RevisitFrame& q) {
  const double error =
      (l.T_map_base.translation() - q.T_world_base_registered->translation()).norm();
  const double angle = rotationErrorDeg(l.T_map_base, *q.T_world_base_registered);
  r.localizations.back().registered_error_m = error;
  r.localizations.back().registered_rotation_error_deg = angle;
  ++r.registered_compared;
  r.registered_below_0_3m += error < 0.3 && angle < 1.0;
  r.mean_registered_error_m += error;
  r.mean_registered_rotation_error_deg += angle;
}

// The counts, errors, wake-ups and time of one run's localizations, whichever method made them.
RevisitResult resultOf(const RevisitExperiment& e, const std::string& name,
                       const LocalizationRun& run) {
  RevisitResult r;
  r.config = name;
  r.dir = name;
  for (const LocalizationRecord& l : run.localizations) {
    r.localizations.push_back(
        {l.frame_index, l.inliers, l.translation_error_m, l.rotation_error_deg});
    r.below_0_5m += l.translation_error_m < 0.5;
    r.below_1m += l.translation_error_m < 1.0;
    r.below_5m += l.translation_error_m < 5.0;
    r.wrong += l.translation_error_m > e.config.wrong_m;
    const auto q = std::find_if(e.queries.begin(), e.queries.end(),
                                [&](const RevisitFrame& f) { return f.frame == l.frame_index; });
    r.revisits_localized +=
        q != e.queries.end() && q->revisit && l.translation_error_m < e.config.correct_m;
    if (q != e.queries.end() && q->T_world_base_registered) compareWithRegistered(r, l, *q);
  }
  if (r.registered_compared > 0) {
    r.mean_registered_error_m /= static_cast<double>(r.registered_compared);
    r.mean_registered_rotation_error_deg /= static_cast<double>(r.registered_compared);
  }
  r.wake_ups = wakeUpsOf(e, r.localizations);
  LocalizationSummary s = summarize(run.localizations);
  // The covariances against the registered ground truth where the scan registered, as the
  // wake-ups are judged (a recorded ground truth can be off by most of a metre at a revisit).
  std::vector<std::pair<const Covariance6*, Eigen::Vector3d>> errors;
  for (const LocalizationRecord& l : run.localizations) {
    const auto q = std::find_if(e.queries.begin(), e.queries.end(),
                                [&](const RevisitFrame& f) { return f.frame == l.frame_index; });
    const std::optional<Pose> reference = q != e.queries.end() && q->T_world_base_registered
                                              ? q->T_world_base_registered
                                              : l.T_world_base;
    if (reference)
      errors.emplace_back(&l.covariance, l.T_map_base.translation() - reference->translation());
  }
  s.share_mahalanobis_within_3 = s.mean_nees = s.median_sigma_m = std::nullopt;
  summarizeCovariances(errors, s);
  r.mean_translation_error_m = s.mean_translation_error_m;
  r.mean_rotation_error_deg = s.mean_rotation_error_deg;
  r.ambiguous = run.ambiguous.size();
  r.share_mahalanobis_within_3 = s.share_mahalanobis_within_3;
  r.mean_nees = s.mean_nees;
  r.median_sigma_m = s.median_sigma_m;
  if (run.stats.frames > 0)
    r.ms_per_query = run.stats.total.total() / static_cast<double>(run.stats.frames);
  return r;
}

RevisitResult segmentResultOf(const RevisitExperiment& e, const NamedConfig& config,
                              const LocalizationRun& run, const BuiltMap& map) {
  RevisitResult r = resultOf(e, config.name, run);
  r.descriptor = map.map->descriptor;
  r.map_segments = map.map->size();
  r.map_bytes = map.bytes;
  return r;
}

void writeRunFiles(const NamedConfig& config, const LocalizationRun& run, const BuiltMap& map,
                   const RevisitExperiment& e, const std::filesystem::path& out) {
  SummaryContext context;
  context.dataset = e.dataset;
  context.map = builtMapPath(out, config).string();
  context.config = config.path.string();
  writeLocalizationRunFiles(out / config.name, run, map, context,
                            e.dataset + ": revisits against its own map, " + config.name);
}

// Where a query frame lies against the mapped ones, noted once for every configuration.
void noteQuery(RevisitExperiment& e, size_t dataset_frame, const Frame& frame,
               const MappedScans& mapped, const Pose& T_base_lidar) {
  RevisitFrame q;
  q.frame = dataset_frame;
  q.nearest_mapped_m = std::numeric_limits<double>::infinity();
  if (frame.T_world_base)
    for (const Eigen::Vector3d& p : mapped.positions)
      q.nearest_mapped_m =
          std::min(q.nearest_mapped_m, (frame.T_world_base->translation() - p).norm());
  q.revisit = q.nearest_mapped_m <= e.config.place_radius_m;
  e.revisits += q.revisit;
  // Every query frame: one farther than place_radius_m may still overlap the map.
  if (mapped.check && frame.T_world_base) {
    if (const auto T = mapped.check->registered(frame.points, *frame.T_world_base * T_base_lidar)) {
      q.T_world_base_registered = *T * T_base_lidar.inverse();
      q.ground_truth_correction_m =
          (q.T_world_base_registered->translation() - frame.T_world_base->translation()).norm();
    }
  }
  e.queries.push_back(q);
}

// How far registration moved the ground truth, over the query frames where it worked.
void summarizeCorrections(RevisitExperiment& e) {
  for (const RevisitFrame& q : e.queries) {
    if (!q.T_world_base_registered) continue;
    ++e.registered;
    e.mean_correction_m += q.ground_truth_correction_m;
    e.max_correction_m = std::max(e.max_correction_m, q.ground_truth_correction_m);
  }
  if (e.registered > 0) e.mean_correction_m /= static_cast<double>(e.registered);
}

// Scan Context's localization of one query frame, on its own, recorded into the session's `run`
// as the sessions record theirs (under the dataset's frame number), its time as the
// localization's.
void localizeByScanContext(const ScanContextLocalizer& scan_context, const Frame& frame,
                           size_t dataset_frame, const DatasetInfo& info, LocalizationRun& run) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::optional<ScanContextLocalization> found = scan_context.localize(frame.points);
  run.stats.total.localize_ms +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ++run.stats.frames;
  if (!run.trajectory_odom.empty())  // driven, as a session counts it
    run.distance_m +=
        (frame.T_odom_base.translation() - run.trajectory_odom.back().translation()).norm();
  run.frames.push_back(stampOf(frame, info));
  run.trajectory_odom.push_back(frame.T_odom_base);
  if (frame.T_world_base) run.trajectory_gt.push_back(*frame.T_world_base);
  if (!found) return;
  LocalizationRecord l;
  l.frame_index = dataset_frame;
  l.frame_number = run.frames.back().number;
  l.timestamp_s = run.frames.back().time_s;
  l.T_map_base = found->T_world_lidar * info.rig.T_base_lidar.inverse();
  l.candidates = 1;
  if (frame.T_world_base) {
    l.T_world_base = *frame.T_world_base;
    l.translation_error_m = translationError(l.T_map_base, *frame.T_world_base);
    l.rotation_error_deg = rotationErrorDeg(l.T_map_base, *frame.T_world_base);
  }
  run.localizations.push_back(std::move(l));
}

RevisitResult scanContextResultOf(const RevisitExperiment& e, const LocalizationRun& run,
                                  const ScanContextLocalizer& scan_context) {
  RevisitResult r = resultOf(e, kScanContextName, run);
  // Scan Context's poses carry no covariance of their own.
  r.share_mahalanobis_within_3 = r.mean_nees = r.median_sigma_m = std::nullopt;
  r.method = kScanContextName;
  r.descriptor = kScanContextName;
  r.mapped_scans = scan_context.size();
  r.map_bytes = scan_context.bytes();
  return r;
}

// Its folder as a configuration's (writeLocalizationRunFiles), with a map of no segments: the
// picture shows the drive and the localizations alone.
void writeScanContextFiles(const LocalizationRun& run, const RevisitResult& r,
                           const RevisitExperiment& e, const std::filesystem::path& out) {
  auto map = std::make_shared<TargetMap>();
  map->descriptor = r.descriptor;
  SummaryContext context;
  context.dataset = e.dataset;
  context.map = "(the mapped scans' scan contexts, in memory)";
  context.config = kScanContextName;
  writeLocalizationRunFiles(out / r.dir, run, BuiltMap{map, r.map_bytes}, context,
                            e.dataset + ": revisits against its own mapped scans, Scan Context");
}

void appendRun(LocalizationRun& all, LocalizationRun run) {
  for (LocalizationRecord& l : run.localizations) all.localizations.push_back(std::move(l));
  for (LocalizationRecord& l : run.ambiguous) all.ambiguous.push_back(std::move(l));
  all.trajectory_gt.insert(all.trajectory_gt.end(), run.trajectory_gt.begin(),
                           run.trajectory_gt.end());
  all.trajectory_odom.insert(all.trajectory_odom.end(), run.trajectory_odom.begin(),
                             run.trajectory_odom.end());
  all.frames.insert(all.frames.end(), run.frames.begin(), run.frames.end());
  all.distance_m += run.distance_m;
  all.stats.frames += run.stats.frames;
  all.stats.total += run.stats.total;
  all.odometry_is_ground_truth |= run.odometry_is_ground_truth;
}

// The query frames, read once for every configuration, on the dataset's odometry: one session
// over them all, or with wake-ups a fresh one (an empty local map) each.
void localizeQueries(FrameSource& source, RevisitExperiment& e,
                     const std::vector<std::shared_ptr<Describer>>& describers,
                     const std::vector<BuiltMap>& maps, const MappedScans& mapped,
                     const std::filesystem::path& out, const ExperimentProgress& progress) {
  const RevisitExperimentConfig& cfg = e.config;
  std::vector<LocalizationRun> runs(cfg.configs.size());
  LocalizationRun scan_context_run;
  for (const std::vector<FrameRange>& ranges : querySessions(cfg)) {
    if (e.interrupted) break;  // no session starts after the stop request
    FrameSubset frames(source, framesOf(ranges));
    std::vector<std::unique_ptr<LocalizationSession>> sessions;
    LocalizationRun scan_context_session;
    for (size_t c = 0; c < cfg.configs.size(); ++c)
      sessions.push_back(std::make_unique<LocalizationSession>(cfg.configs[c].config, source.info(),
                                                               maps[c].map, describers[c]));
    e.interrupted = !forEachFrame(frames, "localize", progress, cfg.stop, [&](const Frame& frame) {
      const size_t dataset_frame = frames.datasetFrame(frame.index);
      noteQuery(e, dataset_frame, frame, mapped, source.info().rig.T_base_lidar);
      for (auto& s : sessions) s->process(frame);
      if (mapped.scan_context)
        localizeByScanContext(*mapped.scan_context, frame, dataset_frame, source.info(),
                              scan_context_session);
    });
    appendRun(scan_context_run, std::move(scan_context_session));
    for (size_t c = 0; c < cfg.configs.size(); ++c) {
      LocalizationRun run = sessions[c]->take();
      // Reported under the dataset's frame numbers, not the subset's.
      for (LocalizationRecord& l : run.localizations)
        l.frame_index = frames.datasetFrame(l.frame_index);
      appendRun(runs[c], std::move(run));
    }
  }
  summarizeCorrections(e);
  for (size_t c = 0; c < cfg.configs.size(); ++c) {
    runs[c].stats.interrupted = e.interrupted;  // its summary.json says so
    e.results.push_back(segmentResultOf(e, cfg.configs[c], runs[c], maps[c]));
    writeRunFiles(cfg.configs[c], runs[c], maps[c], e, out);
  }
  if (mapped.scan_context) {
    scan_context_run.stats.interrupted = e.interrupted;
    e.results.push_back(scanContextResultOf(e, scan_context_run, *mapped.scan_context));
    writeScanContextFiles(scan_context_run, e.results.back(), e, out);
  }
}

namespace {
using Json = nlohmann::ordered_json;
// A registered error is negative where the scan did not register: unknown, so null.
Json known(double value) {
  return value >= 0 ? Json(value) : Json(nullptr);
}
}  // namespace

nlohmann::ordered_json toJson(const RevisitResult& r) {
  const bool compared = r.registered_compared > 0;
  nlohmann::ordered_json loc = nlohmann::ordered_json::array();
  for (const RevisitLocalization& l : r.localizations)
    loc.push_back({{"frame", l.frame},
                   {"inliers", l.inliers},
                   {"translation_error_m", l.translation_error_m},
                   {"rotation_error_deg", l.rotation_error_deg},
                   {"registered_error_m", known(l.registered_error_m)},
                   {"registered_rotation_error_deg", known(l.registered_rotation_error_deg)}});
  nlohmann::ordered_json wake = nlohmann::ordered_json::array();
  for (const WakeUp& w : r.wake_ups)
    wake.push_back({{"first", w.frames.first},
                    {"last", w.frames.last},
                    {"revisit", w.revisit},
                    {"localized_at_frame", w.localized > 0 ? Json(w.localized) : Json(nullptr)},
                    {"wrong_first", w.wrong_first}});
  return {{"config", r.config},
          {"method", r.method},
          {"descriptor", r.descriptor},
          {"model", r.model},
          {"model_note", r.model_note},
          {"map_segments", r.map_segments},
          {"map_bytes", r.map_bytes},
          {"mapped_scans", r.mapped_scans},
          {"ms_per_query", orNull(r.ms_per_query)},
          {"n_localizations", r.localizations.size()},
          {"n_error_below_0_5m", r.below_0_5m},
          {"n_error_below_1m", r.below_1m},
          {"n_error_below_5m", r.below_5m},
          {"n_wrong", r.wrong},
          {"n_ambiguous", r.ambiguous},
          {"covariance_calibration",
           {{"share_mahalanobis_within_3", orNull(r.share_mahalanobis_within_3)},
            {"mean_nees", orNull(r.mean_nees)},
            {"median_sigma_m", orNull(r.median_sigma_m)}}},
          {"mean_translation_error_m", orNull(r.mean_translation_error_m)},
          {"mean_rotation_error_deg", orNull(r.mean_rotation_error_deg)},
          {"n_revisits_localized", r.revisits_localized},
          {"n_registered_compared", r.registered_compared},
          {"n_registered_below_0_3m", r.registered_below_0_3m},
          {"mean_registered_error_m", compared ? Json(r.mean_registered_error_m) : Json(nullptr)},
          {"mean_registered_rotation_error_deg",
           compared ? Json(r.mean_registered_rotation_error_deg) : Json(nullptr)},
          {"dir", r.dir.string()},
          {"wake_ups", wake},
          {"localizations", loc}};
}

std::vector<double> errorsOf(const RevisitResult& r) {
  std::vector<double> errors;
  for (const RevisitLocalization& l : r.localizations) errors.push_back(l.translation_error_m);
  return errors;
}

// The ground truth against the map's geometry, and the localizations against the registered one.
std::string groundTruthCheckText(const RevisitExperiment& e) {
  char line[512];
  std::snprintf(line, sizeof line,
                "\nground truth check: %zu of %zu query scans registered to the mapped scans",
                e.registered, e.queries.size());
  std::string out = line;
  // With none registered, no correction was measured: no "0.00 m on average".
  if (e.registered > 0) {
    std::snprintf(line, sizeof line,
                  "; registration moved their ground truth by %.2f m on average (at most %.2f m)",
                  e.mean_correction_m, e.max_correction_m);
    out += line;
  }
  out += "\n";
  for (const RevisitResult& r : e.results) {
    std::snprintf(line, sizeof line,
                  "%s: against the registered ground truth, %zu of %zu localizations within "
                  "0.3 m and 1 deg, mean error %.2f m / %.2f deg\n",
                  r.config.c_str(), r.registered_below_0_3m, r.registered_compared,
                  r.mean_registered_error_m, r.mean_registered_rotation_error_deg);
    if (r.registered_compared > 0) out += line;
  }
  return out;
}

// The table's "localized by frame k" columns: 1, 2, 3, 5, 10, ... up to the wake-ups' length.
std::vector<size_t> wakeUpColumns(size_t frames) {
  std::vector<size_t> out;
  for (const size_t k : {1, 2, 3, 5, 10, 20, 50})
    if (k < frames) out.push_back(k);
  out.push_back(frames);
  return out;
}

// Which method gave a row: the segments and their descriptor, or Scan Context's whole scans.
std::string methodText(const RevisitResult& r) {
  return r.method == kScanContextName ? "Scan Context (whole scan)"
                                      : r.method + " (" + r.descriptor + ")";
}

std::string msText(const std::optional<double>& ms) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", ms.value_or(0.0));
  return ms ? text : "-";
}

// Counted over the wake-ups at a revisit: elsewhere the map holds nothing to localize against.
std::string wakeUpRow(const RevisitResult& r, const std::vector<size_t>& by) {
  size_t at_revisit = 0, wrong = 0;
  std::vector<size_t> localized(by.size(), 0);
  for (const WakeUp& w : r.wake_ups) {
    if (!w.revisit) continue;
    ++at_revisit;
    wrong += w.wrong_first;
    for (size_t i = 0; i < by.size(); ++i) localized[i] += w.localized > 0 && w.localized <= by[i];
  }
  std::string row =
      "| " + r.config + " | " + methodText(r) + " | " + std::to_string(at_revisit) + " |";
  for (const size_t n : localized) row += " " + std::to_string(n) + " |";
  return row + " " + std::to_string(wrong) + " | " + msText(r.ms_per_query) + " |";
}

}  // namespace

std::vector<FrameRange> parseFrameRanges(const std::string& text, const std::string& what) {
  std::vector<FrameRange> ranges;
  std::stringstream items(text);
  std::string item;
  auto number = [&](const std::string& s) {
    if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos)
      throw std::invalid_argument(what + ": '" + text + "' is not A:B[,C:D...] of frame numbers");
    return static_cast<size_t>(std::stoull(s));
  };
  while (std::getline(items, item, ',')) {
    const size_t colon = item.find(':');
    FrameRange r;
    r.first = number(item.substr(0, colon));
    r.last = colon == std::string::npos ? r.first : number(item.substr(colon + 1));
    if (r.last < r.first)
      throw std::invalid_argument(what + ": " + item + " ends before it starts");
    ranges.push_back(r);
  }
  if (ranges.empty()) throw std::invalid_argument(what + ": no frames given");
  return ranges;
}

void parseWakeUp(const std::string& text, const std::string& what, RevisitExperimentConfig& c) {
  const size_t slash = text.find('/');
  auto number = [&](const std::string& s) {
    if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos ||
        std::stoul(s) == 0)
      throw std::invalid_argument(what + ": '" + text +
                                  "' is not N[/EVERY] of positive frame counts");
    return static_cast<size_t>(std::stoul(s));
  };
  c.wake_up_frames = number(text.substr(0, slash));
  c.wake_up_every = slash == std::string::npos ? 0 : number(text.substr(slash + 1));
  if (c.wake_up_every != 0 && c.wake_up_every < c.wake_up_frames)
    throw std::invalid_argument(what + ": " + text +
                                " would wake up again before the last wake-up's frames end");
}

std::vector<std::vector<FrameRange>> querySessions(const RevisitExperimentConfig& c) {
  if (c.wake_up_frames == 0) return {c.query_frames};
  const size_t every = c.wake_up_every ? c.wake_up_every : c.wake_up_frames;
  std::vector<std::vector<FrameRange>> out;
  for (const FrameRange& r : c.query_frames)
    for (size_t first = r.first; first <= r.last; first += every)
      out.push_back({FrameRange{first, std::min(first + c.wake_up_frames - 1, r.last)}});
  return out;
}

RevisitExperiment evaluateRevisits(FrameSource& source, const RevisitExperimentConfig& cfg,
                                   const std::filesystem::path& out,
                                   const ExperimentProgress& progress) {
  checkRevisitInput(source, cfg);
  RevisitExperiment e;
  e.config = cfg;
  e.dataset = source.info().name;
  e.odometry_is_ground_truth = source.info().odometry_is_ground_truth;
  for (int i = 0; i <= 100; ++i) e.thresholds.push_back(cfg.wrong_m * i / 100.0);
  std::filesystem::create_directories(out / "maps");
  // Models load first: a missing one fails before the frames are read. Map and queries come
  // from one recording, so one model suits both.
  const InputModalities input = inputModalitiesOf(source.info());
  std::vector<DescriptorChoice> choices;
  std::vector<std::shared_ptr<Describer>> describers;
  for (const NamedConfig& c : cfg.configs) {
    choices.push_back(chooseDescriptor(c.config.descriptor, input));
    describers.push_back(makeDescriber(choices.back().descriptor));
  }
  MappedScans mapped;
  if (cfg.check_ground_truth) mapped.check.emplace();
  if (cfg.scan_context)
    mapped.scan_context.emplace(*cfg.scan_context, source.info().rig.T_base_lidar);
  const std::vector<BuiltMap> maps = buildMaps(source, e, describers, out, mapped, progress);
  localizeQueries(source, e, describers, maps, mapped, out, progress);
  for (size_t c = 0; c < cfg.configs.size(); ++c) {  // Scan Context's result follows theirs
    e.results[c].model = choices[c].descriptor.model;
    e.results[c].model_note = choices[c].note;
  }
  return e;
}

nlohmann::ordered_json toJson(const RevisitExperiment& e) {
  nlohmann::ordered_json j;
  j["dataset"] = e.dataset;
  j["interrupted"] = e.interrupted;  // `queries` are those done before Ctrl-C
  auto ranges = [](const std::vector<FrameRange>& rs) {
    nlohmann::ordered_json a = nlohmann::ordered_json::array();
    for (const FrameRange& r : rs) a.push_back({r.first, r.last});
    return a;
  };
  j["map_frames"] = ranges(e.config.map_frames);
  j["query_frames"] = ranges(e.config.query_frames);
  j["place_radius_m"] = e.config.place_radius_m;
  j["correct_m"] = e.config.correct_m;
  j["wrong_m"] = e.config.wrong_m;
  j["wake_up_frames"] = e.config.wake_up_frames;
  j["wake_up_every"] = e.config.wake_up_every;
  j["odometry_is_ground_truth"] = e.odometry_is_ground_truth;
  j["n_queries"] = e.queries.size();
  j["n_revisits"] = e.revisits;
  j["queries"] = nlohmann::ordered_json::array();
  j["check_ground_truth"] = e.config.check_ground_truth;
  j["n_registered"] = e.registered;
  // Nothing registered: no correction measured, not a zero one.
  const bool registered = e.registered > 0;
  j["mean_ground_truth_correction_m"] = registered ? Json(e.mean_correction_m) : Json(nullptr);
  j["max_ground_truth_correction_m"] = registered ? Json(e.max_correction_m) : Json(nullptr);
  for (const RevisitFrame& q : e.queries) {
    nlohmann::ordered_json f = {
        {"frame", q.frame}, {"nearest_mapped_m", q.nearest_mapped_m}, {"revisit", q.revisit}};
    if (q.T_world_base_registered) f["ground_truth_correction_m"] = q.ground_truth_correction_m;
    j["queries"].push_back(f);
  }
  j["results"] = nlohmann::ordered_json::array();
  for (const RevisitResult& r : e.results) j["results"].push_back(toJson(r));
  return j;
}

void writeRevisitFiles(const RevisitExperiment& e, const std::filesystem::path& out) {
  std::filesystem::create_directories(out);
  writeJsonAtomically(out / "revisits.json", toJson(e));
  viz::Panel p;
  p.title = std::to_string(e.queries.size()) + " query frames, " + std::to_string(e.revisits) +
            " at a mapped place";
  p.xlabel = "translation error threshold (m)";
  p.ylabel = "localizations within the threshold";
  p.style = viz::PlotStyle::kSteps;
  p.auto_y = true;
  for (const RevisitResult& r : e.results) {
    viz::Series s;
    s.name = r.config;
    s.x = e.thresholds;
    for (size_t v : cumulativeCounts(errorsOf(r), e.thresholds))
      s.y.push_back(static_cast<double>(v));
    p.series.push_back(std::move(s));
  }
  viz::plotPanels(out / "revisits.png", "Revisits of " + e.dataset, {p});
}

std::string revisitTable(const RevisitExperiment& e) {
  std::ostringstream t;
  t << "| config | method | localizations | < 0.5 m | < 1 m | < 5 m | wrong (> " << e.config.wrong_m
    << " m) | mean error | revisits localized (< " << e.config.correct_m << " m) | ms / query |\n"
    << "| --- | --- | ---: | ---: | ---: | ---: | ---: | --- | ---: | ---: |\n";
  char line[512];
  for (const RevisitResult& r : e.results) {
    std::snprintf(line, sizeof(line),
                  "| %s | %s | %zu | %zu | %zu | %zu | %zu | %s | %zu of %zu | %s |\n",
                  r.config.c_str(), methodText(r).c_str(), r.localizations.size(), r.below_0_5m,
                  r.below_1m, r.below_5m, r.wrong,
                  meanErrorText(r.mean_translation_error_m, r.mean_rotation_error_deg).c_str(),
                  r.revisits_localized, e.revisits, msText(r.ms_per_query).c_str());
    t << line;
  }
  if (e.odometry_is_ground_truth)
    t << "\n[odometry is the ground truth]: the errors are measured against the poses that the "
         "query "
         "frames' local maps were built on\n";
  if (e.config.check_ground_truth) t << groundTruthCheckText(e);
  if (e.config.wake_up_frames > 0) {
    if (e.config.check_ground_truth)
      t << "\nwake-ups judged against the registered ground truth where the scan registered\n";
    t << "\n| config | method | wake-ups at a revisit |";
    const std::vector<size_t> by = wakeUpColumns(e.config.wake_up_frames);
    for (const size_t k : by) t << " localized by frame " << k << " |";
    t << " first localization wrong | ms / query |\n| --- | --- | ---: |";
    for (size_t i = 0; i <= by.size() + 1; ++i) t << " ---: |";
    t << "\n";
    for (const RevisitResult& r : e.results) t << wakeUpRow(r, by) << "\n";
  }
  for (const RevisitResult& r : e.results)
    if (!r.model_note.empty()) t << "\n" << r.config << ": " << r.model_note << "\n";
  if (e.interrupted) t << partialNote();
  return t.str();
}

}  // namespace semsegmap
