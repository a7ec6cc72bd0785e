#include "semsegmap/eval/localization_experiment.h"

#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "semsegmap/eval/localization_metrics.h"
#include "semsegmap/eval/localization_picture.h"
#include "semsegmap/io/atomic_file.h"
#include "semsegmap/io/json.h"
#include "semsegmap/io/open_dataset.h"
#include "semsegmap/localize/map_file.h"
#include "semsegmap/pipeline/run_output.h"
#include "semsegmap/viz/plot.h"

namespace semsegmap {

namespace {

LocalizationResult resultOf(const LocalizationExperimentConfig& cfg, const NamedConfig& config,
                            const std::string& run_name, const LocalizationRun& run,
                            const TargetMap& map, uint64_t map_bytes) {
  LocalizationResult r;
  r.config = config.name;
  r.descriptor = map.descriptor;
  r.fingerprint = map.fingerprint;
  r.run = run_name;
  r.frames = run.stats.frames;
  r.summary = summarize(run.localizations);
  r.hz = run.stats.fps();
  const double n = std::max<double>(1.0, static_cast<double>(run.stats.frames));
  const StageTimes& t = run.stats.total;
  r.per_frame = {t.enrich_ms / n, t.local_map_ms / n, t.segment_ms / n, t.describe_ms / n,
                 t.localize_ms / n};
  r.map_segments = map.size();
  r.map_bytes = map_bytes;
  const std::vector<double> travelled = travelledDistances(run.trajectory_gt);
  r.distance_m = travelled.empty() ? 0.0 : travelled.back();
  std::vector<size_t> correct;
  for (const LocalizationRecord& l : run.localizations) {
    if (!l.T_map_robot_gt) continue;
    r.errors.push_back(l.translation_error_m);
    r.wrong += l.translation_error_m > cfg.wrong_m;
    // Frames are numbered from 0 in the order they are run (forEachFrame checks).
    if (l.translation_error_m < cfg.correct_m) correct.push_back(l.frame_index);
  }
  r.wrong_rate = run.localizations.empty()
                     ? 0.0
                     : static_cast<double>(r.wrong) / static_cast<double>(run.localizations.size());
  r.recall = recallAlongTrajectory(travelled, correct, cfg.recall_window_m);
  return r;
}

std::string resultJson(const LocalizationResult& r, const std::vector<size_t>& curve) {
  std::ostringstream j;
  const LocalizationSummary& s = r.summary;
  j << "    {\"config\": " << jsonQuoted(r.config)
    << ", \"descriptor\": " << jsonQuoted(r.descriptor) << ", \"run\": " << jsonQuoted(r.run)
    << ", \"dataset\": " << jsonQuoted(r.dataset) << ", \"frames\": " << r.frames
    << ", \"distance_m\": " << r.distance_m << ",\n     \"n_localizations\": " << s.localizations
    << ", \"n_error_below_1m\": " << s.below_1m << ", \"n_error_below_5m\": " << s.below_5m
    << ", \"mean_translation_error_m\": " << s.mean_translation_error_m
    << ", \"mean_rotation_error_deg\": " << s.mean_rotation_error_deg
    << ",\n     \"n_wrong\": " << r.wrong << ", \"wrong_rate\": " << r.wrong_rate
    << ", \"recall_along_trajectory\": " << r.recall << ", \"fps\": " << r.hz
    << ", \"stage_ms\": {\"enrich\": " << r.per_frame.enrich_ms
    << ", \"local_map\": " << r.per_frame.local_map_ms
    << ", \"segment\": " << r.per_frame.segment_ms << ", \"describe\": " << r.per_frame.describe_ms
    << ", \"localize\": " << r.per_frame.localize_ms << "}"
    << ",\n     \"map_segments\": " << r.map_segments << ", \"map_bytes\": " << r.map_bytes
    << ", \"dir\": " << jsonQuoted(r.dir.string()) << ",\n     \"cumulative\": [";
  for (size_t i = 0; i < curve.size(); ++i) j << (i ? ", " : "") << curve[i];
  j << "]}";
  return j.str();
}

}  // namespace

std::pair<int, int> paperLocalizations(const std::string& run, const std::string& preset) {
  if (preset != "full") return {-1, -1};
  if (run == "S2") return {126, 258};
  if (run == "S3") return {10, 108};
  return {-1, -1};
}

LocalizationExperiment runLocalizationExperiment(const LocalizationExperimentConfig& cfg,
                                                 const std::filesystem::path& out,
                                                 const ExperimentProgress& progress) {
  if (cfg.configs.empty())
    throw std::invalid_argument("the localization experiment needs at least one configuration");
  LocalizationExperiment e;
  e.config = cfg;
  for (int i = 0; i <= 100; ++i) e.thresholds.push_back(cfg.wrong_m * i / 100.0);
  std::filesystem::create_directories(out / "maps");

  // Models load first: a missing one fails before minutes of simulation.
  std::vector<std::unique_ptr<Describer>> describers;
  for (const NamedConfig& c : cfg.configs) describers.push_back(makeDescriber(c.config.descriptor));

  // The map run, rendered once for every configuration.
  std::vector<TargetMap> maps;
  std::vector<uint64_t> map_bytes;
  {
    auto source =
        openDataset(simulatedRunSpec(cfg.world_seed, cfg.map_run, cfg.preset, cfg.max_frames));
    std::vector<std::unique_ptr<MappingSession>> sessions;
    for (size_t c = 0; c < cfg.configs.size(); ++c) {
      PipelineConfig pc = cfg.configs[c].config;
      pc.target_map.max_points_per_segment = cfg.picture_points_per_segment;
      sessions.push_back(std::make_unique<MappingSession>(
          pc, source->info(), PoseSource::kGroundTruth, *describers[c]));
    }
    forEachFrame(*source, "map " + cfg.map_run, progress, [&](const Frame& frame) {
      for (auto& s : sessions) s->process(frame);
    });
    for (size_t c = 0; c < cfg.configs.size(); ++c) {
      maps.push_back(sessions[c]->finish().map);
      // The saved map is what a robot carries: without the picture points.
      TargetMap saved = maps.back();
      for (MapSegment& s : saved.segments) s.points.clear();
      map_bytes.push_back(saveTargetMap(out / "maps" / (cfg.configs[c].name + ".map"), saved));
    }
  }

  for (const std::string& run_name : cfg.query_runs) {
    auto source =
        openDataset(simulatedRunSpec(cfg.world_seed, run_name, cfg.preset, cfg.max_frames));
    std::vector<std::unique_ptr<LocalizationSession>> sessions;
    for (size_t c = 0; c < cfg.configs.size(); ++c)
      sessions.push_back(std::make_unique<LocalizationSession>(
          cfg.configs[c].config, source->info(), maps[c], *describers[c]));
    forEachFrame(*source, "localize " + run_name, progress, [&](const Frame& frame) {
      for (auto& s : sessions) s->process(frame);
    });
    for (size_t c = 0; c < cfg.configs.size(); ++c) {
      const NamedConfig& config = cfg.configs[c];
      const LocalizationRun run = sessions[c]->take();
      LocalizationResult r = resultOf(cfg, config, run_name, run, maps[c], map_bytes[c]);
      r.dataset = source->info().name;
      r.dir = config.name + "_" + run_name;
      const std::filesystem::path dir = out / r.dir;
      std::filesystem::create_directories(dir);
      writeLocalizationsCsv(dir / "localizations.csv", run);
      SummaryContext context;
      context.dataset = r.dataset;
      context.map = (out / "maps" / (config.name + ".map")).string();
      context.config = config.path.string();
      context.descriptor = maps[c].descriptor;
      context.map_segments = maps[c].size();
      context.map_bytes = map_bytes[c];
      writeBytesAtomically(dir / "summary.json", localizationSummaryJson(run, context));
      writeLocalizationPicture(dir / "localization.png", run, maps[c],
                               run_name + " (" + source->info().name + ") against the " +
                                   cfg.map_run + " map, " + config.name);
      e.results.push_back(std::move(r));
    }
  }

  // The paper's accuracy figure: localizations within each error threshold.
  std::vector<viz::Panel> panels;
  std::ostringstream json;
  json << "{\n  \"world_seed\": " << cfg.world_seed << ",\n  \"preset\": " << jsonQuoted(cfg.preset)
       << ",\n  \"map_run\": " << jsonQuoted(cfg.map_run) << ",\n  \"correct_m\": " << cfg.correct_m
       << ",\n  \"wrong_m\": " << cfg.wrong_m << ",\n  \"recall_window_m\": " << cfg.recall_window_m
       << ",\n  \"thresholds_m\": [";
  for (size_t i = 0; i < e.thresholds.size(); ++i) json << (i ? ", " : "") << e.thresholds[i];
  json << "],\n  \"results\": [\n";
  for (const std::string& run_name : cfg.query_runs) {
    viz::Panel p;
    p.title = run_name;
    p.xlabel = "translation error threshold (m)";
    p.ylabel = "localizations within the threshold";
    p.style = viz::PlotStyle::kSteps;
    p.auto_y = true;
    for (const LocalizationResult& r : e.results) {
      if (r.run != run_name) continue;
      const std::vector<size_t> curve = cumulativeCounts(r.errors, e.thresholds);
      viz::Series s;
      s.name = r.config;
      s.x = e.thresholds;
      for (size_t v : curve) s.y.push_back(static_cast<double>(v));
      p.series.push_back(std::move(s));
      json << (&r == &e.results.front() ? "" : ",\n") << resultJson(r, curve);
    }
    panels.push_back(std::move(p));
  }
  json << "\n  ]\n}\n";
  writeBytesAtomically(out / "localization.json", json.str());
  viz::plotPanels(out / "localization_accuracy.png",
                  "Localizations against the " + cfg.map_run + " map (world " +
                      std::to_string(cfg.world_seed) + ", " + cfg.preset + ")",
                  panels);
  return e;
}

std::string localizationTable(const LocalizationExperiment& e) {
  std::ostringstream t;
  t << "| run | config | localizations | < 1 m | < 5 m | wrong (> 5 m) | mean error | recall "
       "(20 m) | Hz | map segments | map KB | paper |\n"
       "| --- | --- | ---: | ---: | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: |\n";
  char line[512];
  for (const LocalizationResult& r : e.results) {
    const auto paper = paperLocalizations(r.run, e.config.preset);
    const bool semantic = r.config.find("semsegmap") != std::string::npos;
    const int paper_n = semantic ? paper.second : paper.first;
    std::snprintf(line, sizeof(line),
                  "| %s | %s | %zu | %zu | %zu | %zu | %.2f m / %.2f° | %.2f | %.1f | %zu | %.1f | "
                  "%s |\n",
                  r.run.c_str(), r.config.c_str(), r.summary.localizations, r.summary.below_1m,
                  r.summary.below_5m, r.wrong, r.summary.mean_translation_error_m,
                  r.summary.mean_rotation_error_deg, r.recall, r.hz, r.map_segments,
                  static_cast<double>(r.map_bytes) / 1024.0,
                  paper_n >= 0 ? std::to_string(paper_n).c_str() : "-");
    t << line;
  }
  return t.str();
}

}  // namespace semsegmap
