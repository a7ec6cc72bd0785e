#include "semsegmap/eval/revisit_experiment.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/eval/localization_files.h"
#include "semsegmap/eval/localization_metrics.h"
#include "semsegmap/io/model_file.h"
#include "semsegmap/io/run_output.h"
#include "semsegmap/viz/plot.h"

namespace semsegmap {

namespace {

// Some frames of a dataset, numbered from 0 in the order given, as the sessions and
// forEachFrame expect; `datasetFrame` maps a number back.
class FrameSubset : public FrameSource {
 public:
  FrameSubset(FrameSource& source, std::vector<size_t> frames)
      : source_(source), frames_(std::move(frames)) {}
  const DatasetInfo& info() const override { return source_.info(); }
  size_t size() const override { return frames_.size(); }
  Frame frame(size_t index) override {
    Frame f = source_.frame(frames_.at(index));
    f.index = index;
    return f;
  }
  double frameTime(size_t index) override { return source_.frameTime(frames_.at(index)); }
  size_t datasetFrame(size_t index) const { return frames_.at(index); }

 private:
  FrameSource& source_;
  std::vector<size_t> frames_;
};

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
}

// The map frames, read once for every configuration, on ground-truth poses; their ground-truth
// positions go to `mapped_positions`.
std::vector<BuiltMap> buildMaps(FrameSource& source, const RevisitExperimentConfig& cfg,
                                const std::vector<std::shared_ptr<Describer>>& describers,
                                const std::filesystem::path& out,
                                std::vector<Eigen::Vector3d>& mapped_positions,
                                const ExperimentProgress& progress) {
  FrameSubset frames(source, framesOf(cfg.map_frames));
  auto sessions =
      mappingSessions(cfg.configs, source.info(), describers, cfg.picture_points_per_segment);
  forEachFrame(frames, "map", progress, [&](const Frame& frame) {
    if (!frame.T_world_base)
      throw std::runtime_error(source.info().name + ": frame " +
                               std::to_string(frames.datasetFrame(frame.index)) +
                               " has no ground-truth pose");
    mapped_positions.push_back(frame.T_world_base->translation());
    for (auto& s : sessions) s->process(frame);
  });
  return finishMaps(sessions, cfg.configs, out);
}

RevisitResult resultOf(const RevisitExperiment& e, const NamedConfig& config,
                       const LocalizationRun& run, const BuiltMap& map) {
  RevisitResult r;
  r.config = config.name;
  r.descriptor = map.map->descriptor;
  r.map_segments = map.map->size();
  r.map_bytes = map.bytes;
  r.dir = config.name;
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
  }
  const LocalizationSummary s = summarize(run.localizations);
  r.mean_translation_error_m = s.mean_translation_error_m;
  r.mean_rotation_error_deg = s.mean_rotation_error_deg;
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

// The query frames, read once for every configuration, on the dataset's odometry.
void localizeQueries(FrameSource& source, RevisitExperiment& e,
                     const std::vector<std::shared_ptr<Describer>>& describers,
                     const std::vector<BuiltMap>& maps,
                     const std::vector<Eigen::Vector3d>& mapped_positions,
                     const std::filesystem::path& out, const ExperimentProgress& progress) {
  const RevisitExperimentConfig& cfg = e.config;
  FrameSubset frames(source, framesOf(cfg.query_frames));
  std::vector<std::unique_ptr<LocalizationSession>> sessions;
  for (size_t c = 0; c < cfg.configs.size(); ++c)
    sessions.push_back(std::make_unique<LocalizationSession>(cfg.configs[c].config, source.info(),
                                                             maps[c].map, describers[c]));
  forEachFrame(frames, "localize", progress, [&](const Frame& frame) {
    RevisitFrame q;
    q.frame = frames.datasetFrame(frame.index);
    q.nearest_mapped_m = std::numeric_limits<double>::infinity();
    if (frame.T_world_base)
      for (const Eigen::Vector3d& p : mapped_positions)
        q.nearest_mapped_m =
            std::min(q.nearest_mapped_m, (frame.T_world_base->translation() - p).norm());
    q.revisit = q.nearest_mapped_m <= cfg.place_radius_m;
    e.revisits += q.revisit;
    e.queries.push_back(q);
    for (auto& s : sessions) s->process(frame);
  });
  for (size_t c = 0; c < cfg.configs.size(); ++c) {
    LocalizationRun run = sessions[c]->take();
    // Reported under the dataset's frame numbers, not the subset's.
    for (LocalizationRecord& l : run.localizations)
      l.frame_index = frames.datasetFrame(l.frame_index);
    e.results.push_back(resultOf(e, cfg.configs[c], run, maps[c]));
    writeRunFiles(cfg.configs[c], run, maps[c], e, out);
  }
}

nlohmann::ordered_json toJson(const RevisitResult& r) {
  nlohmann::ordered_json loc = nlohmann::ordered_json::array();
  for (const RevisitLocalization& l : r.localizations)
    loc.push_back({{"frame", l.frame},
                   {"inliers", l.inliers},
                   {"translation_error_m", l.translation_error_m},
                   {"rotation_error_deg", l.rotation_error_deg}});
  return {{"config", r.config},
          {"descriptor", r.descriptor},
          {"map_segments", r.map_segments},
          {"map_bytes", r.map_bytes},
          {"n_localizations", r.localizations.size()},
          {"n_error_below_0_5m", r.below_0_5m},
          {"n_error_below_1m", r.below_1m},
          {"n_error_below_5m", r.below_5m},
          {"n_wrong", r.wrong},
          {"mean_translation_error_m", r.mean_translation_error_m},
          {"mean_rotation_error_deg", r.mean_rotation_error_deg},
          {"n_revisits_localized", r.revisits_localized},
          {"dir", r.dir.string()},
          {"localizations", loc}};
}

std::vector<double> errorsOf(const RevisitResult& r) {
  std::vector<double> errors;
  for (const RevisitLocalization& l : r.localizations) errors.push_back(l.translation_error_m);
  return errors;
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

RevisitExperiment evaluateRevisits(FrameSource& source, const RevisitExperimentConfig& cfg,
                                   const std::filesystem::path& out,
                                   const ExperimentProgress& progress) {
  checkRevisitInput(source, cfg);
  RevisitExperiment e;
  e.config = cfg;
  e.dataset = source.info().name;
  for (int i = 0; i <= 100; ++i) e.thresholds.push_back(cfg.wrong_m * i / 100.0);
  std::filesystem::create_directories(out / "maps");
  // Models load first: a missing one fails before the frames are read.
  std::vector<std::shared_ptr<Describer>> describers;
  for (const NamedConfig& c : cfg.configs) describers.push_back(makeDescriber(c.config.descriptor));
  std::vector<Eigen::Vector3d> mapped_positions;
  const std::vector<BuiltMap> maps =
      buildMaps(source, cfg, describers, out, mapped_positions, progress);
  localizeQueries(source, e, describers, maps, mapped_positions, out, progress);
  return e;
}

nlohmann::ordered_json toJson(const RevisitExperiment& e) {
  nlohmann::ordered_json j;
  j["dataset"] = e.dataset;
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
  j["n_queries"] = e.queries.size();
  j["n_revisits"] = e.revisits;
  j["queries"] = nlohmann::ordered_json::array();
  for (const RevisitFrame& q : e.queries)
    j["queries"].push_back(
        {{"frame", q.frame}, {"nearest_mapped_m", q.nearest_mapped_m}, {"revisit", q.revisit}});
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
  t << "| config | localizations | < 0.5 m | < 1 m | < 5 m | wrong (> " << e.config.wrong_m
    << " m) | mean error | revisits localized (< " << e.config.correct_m << " m) |\n"
    << "| --- | ---: | ---: | ---: | ---: | ---: | --- | ---: |\n";
  char line[512], mean[64];
  for (const RevisitResult& r : e.results) {
    // No localization has no mean error, not a zero one.
    std::snprintf(mean, sizeof(mean), "%.2f m / %.2f°", r.mean_translation_error_m,
                  r.mean_rotation_error_deg);
    std::snprintf(line, sizeof(line), "| %s | %zu | %zu | %zu | %zu | %zu | %s | %zu of %zu |\n",
                  r.config.c_str(), r.localizations.size(), r.below_0_5m, r.below_1m, r.below_5m,
                  r.wrong, r.localizations.empty() ? "-" : mean, r.revisits_localized, e.revisits);
    t << line;
  }
  return t.str();
}

}  // namespace semsegmap
