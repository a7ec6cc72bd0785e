#include "semsegmap/eval/localization_experiment.h"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/datasets/semantic_sources.h"
#include "semsegmap/eval/localization_files.h"
#include "semsegmap/eval/localization_metrics.h"
#include "semsegmap/outputs/run_output.h"
#include "semsegmap/viz/plot.h"

namespace semsegmap {

namespace {

using PassLabelers = std::vector<std::unique_ptr<ReplayLabeler>>;
// Indexed [pass][configuration]: a pass may describe with a model of its own (LabelPass).
using PassDescribers = std::vector<std::vector<std::shared_ptr<Describer>>>;

// Each pass's labeler: none for the simulator's labels; else its network, loaded and checked
// against the run's cameras before any frame is read.
PassLabelers passLabelers(const LocalizationExperimentConfig& cfg, const DatasetInfo& info) {
  PassLabelers labelers;
  for (const LabelPass& pass : cfg.label_passes) {
    if (pass.network.model.empty()) {
      labelers.push_back(nullptr);
      continue;
    }
    SemanticsConfig network = pass.network;
    network.replace_dataset_labels = true;  // the simulator's are perfect
    labelers.push_back(std::make_unique<ReplayLabeler>(
        loadSegmentationNetwork(network, info, cfg.class_maps_dir), info.rig.T_base_lidar));
  }
  return labelers;
}

// The configurations as a pass runs them.
std::vector<NamedConfig> passConfigs(const LocalizationExperimentConfig& cfg,
                                     const LabelPass& pass) {
  std::vector<NamedConfig> configs = cfg.configs;
  for (NamedConfig& c : configs) {
    if (pass.geometric_ground_removal) c.config.local_map.geometric_ground_removal = true;
    if (!pass.descriptor_model.empty() && c.config.descriptor.kind == pass.descriptor_kind)
      c.config.descriptor.model = pass.descriptor_model;
  }
  return configs;
}

// Each configuration's describer, loaded once and shared by the passes that describe with its
// model; a pass with a model of its own (LabelPass::descriptor_model) gets that model's.
PassDescribers passDescribers(const LocalizationExperimentConfig& cfg) {
  std::map<std::pair<size_t, std::string>, std::shared_ptr<Describer>> loaded;
  PassDescribers describers;
  for (const LabelPass& pass : cfg.label_passes) {
    const std::vector<NamedConfig> configs = passConfigs(cfg, pass);
    describers.emplace_back();
    for (size_t c = 0; c < configs.size(); ++c) {
      std::shared_ptr<Describer>& describer = loaded[{c, configs[c].config.descriptor.model}];
      if (!describer) describer = makeDescriber(configs[c].config.descriptor);
      describers.back().push_back(describer);
    }
  }
  return describers;
}

// Hands each pass its frame: the rendered one, or a copy that the pass's network labels.
void feedPasses(const Frame& frame, const PassLabelers& labelers,
                const std::function<void(size_t pass, const Frame&)>& use) {
  for (size_t p = 0; p < labelers.size(); ++p) {
    if (!labelers[p]) {
      use(p, frame);
      continue;
    }
    Frame labelled = frame;
    labelers[p]->label(labelled, "frame " + std::to_string(frame.index));
    use(p, labelled);
  }
}

// The map run, rendered once for every pass and configuration; each map is saved into
// out/<pass dir>/maps/ (when interrupted, the map of the frames done: a whole map of a shorter
// run). Indexed [pass][configuration].
std::vector<std::vector<BuiltMap>> buildMaps(LocalizationExperiment& e,
                                             const PassDescribers& describers,
                                             const std::filesystem::path& out,
                                             const ExperimentProgress& progress) {
  const LocalizationExperimentConfig& cfg = e.config;
  auto source = openDataset(simulatedRunSpec(cfg.world_seed, cfg.map_run, cfg.preset,
                                             cfg.max_frames, cfg.label_noise, cfg.rig));
  const PassLabelers labelers = passLabelers(cfg, source->info());
  std::vector<std::vector<std::unique_ptr<MappingSession>>> sessions;
  for (size_t p = 0; p < cfg.label_passes.size(); ++p)
    sessions.push_back(mappingSessions(passConfigs(cfg, cfg.label_passes[p]), source->info(),
                                       describers[p], cfg.picture_points_per_segment));
  e.interrupted =
      !forEachFrame(*source, "map " + cfg.map_run, progress, cfg.stop, [&](const Frame& frame) {
        feedPasses(frame, labelers, [&](size_t p, const Frame& f) {
          for (auto& s : sessions[p]) s->process(f);
        });
      });
  std::vector<std::vector<BuiltMap>> maps;
  for (size_t p = 0; p < sessions.size(); ++p)
    maps.push_back(finishMaps(sessions[p], passConfigs(cfg, cfg.label_passes[p]),
                              out / cfg.label_passes[p].dir));
  return maps;
}

LocalizationResult resultOf(const LocalizationExperiment& e, const NamedConfig& config,
                            const std::string& run_name, const LocalizationRun& run,
                            const BuiltMap& map) {
  const LocalizationExperimentConfig& cfg = e.config;
  LocalizationResult r;
  r.config = config.name;
  r.descriptor = map.map->descriptor;
  r.fingerprint = map.map->fingerprint;
  r.run = run_name;
  r.frames = run.stats.frames;
  r.summary = summarize(run);
  r.hz = run.stats.fps();
  r.per_frame = meanStageTimes(run.stats);
  r.map_segments = map.map->size();
  r.map_bytes = map.bytes;
  const std::vector<double> travelled = travelledDistances(run.trajectory_gt);
  r.distance_m = travelled.empty() ? 0.0 : travelled.back();
  std::vector<size_t> correct;
  for (const LocalizationRecord& l : run.localizations) {
    if (!l.T_world_base) continue;
    r.errors.push_back(l.translation_error_m);
    r.wrong += l.translation_error_m > cfg.wrong_m;
    // Frames are numbered from 0 in the order they are run (forEachFrame checks).
    if (l.translation_error_m < cfg.correct_m) correct.push_back(l.frame_index);
  }
  r.wrong_rate = run.localizations.empty()
                     ? 0.0
                     : static_cast<double>(r.wrong) / static_cast<double>(run.localizations.size());
  r.recall = recallAlongTrajectory(travelled, correct, cfg.recall_window_m);
  r.cumulative = cumulativeCounts(r.errors, e.thresholds);
  r.dir = config.name + "_" + run_name;
  return r;
}

// What one configuration's run leaves behind in out/<r.dir>.
void writeRunFiles(const LocalizationExperimentConfig& cfg, const NamedConfig& config,
                   const LocalizationRun& run, const BuiltMap& map, const LocalizationResult& r,
                   const std::filesystem::path& out, const LabelPass& pass) {
  SummaryContext context;
  context.dataset = r.dataset;
  context.map = builtMapPath(out / pass.dir, config).string();
  context.config = config.path.string();
  writeLocalizationRunFiles(
      out / r.dir, run, map, context,
      r.run + " (" + r.dataset + ") against the " + cfg.map_run + " map, " + config.name);
}

// One query run, rendered once for every pass and configuration.
void localizeRun(LocalizationExperiment& e, const std::string& run_name,
                 const PassDescribers& describers, const std::vector<std::vector<BuiltMap>>& maps,
                 const std::filesystem::path& out, const ExperimentProgress& progress) {
  const LocalizationExperimentConfig& cfg = e.config;
  DatasetOptions options;
  if (cfg.lidar_odometry) {
    options.odometry = "lidar";
    options.lidar_odometry = cfg.odometry;
  }
  auto source = openDataset(simulatedRunSpec(cfg.world_seed, run_name, cfg.preset, cfg.max_frames,
                                             cfg.label_noise, cfg.rig),
                            options);
  const PassLabelers labelers = passLabelers(cfg, source->info());
  std::vector<std::vector<std::unique_ptr<LocalizationSession>>> sessions(labelers.size());
  for (size_t p = 0; p < labelers.size(); ++p) {
    const std::vector<NamedConfig> configs = passConfigs(cfg, cfg.label_passes[p]);
    for (size_t c = 0; c < configs.size(); ++c)
      sessions[p].push_back(std::make_unique<LocalizationSession>(
          configs[c].config, source->info(), maps[p][c].map, describers[p][c]));
  }
  e.interrupted =
      !forEachFrame(*source, "localize " + run_name, progress, cfg.stop, [&](const Frame& frame) {
        feedPasses(frame, labelers, [&](size_t p, const Frame& f) {
          for (auto& s : sessions[p]) s->process(f);
        });
      });
  for (size_t p = 0; p < labelers.size(); ++p) {
    const LabelPass& pass = cfg.label_passes[p];
    for (size_t c = 0; c < cfg.configs.size(); ++c) {
      LocalizationRun run = sessions[p][c]->take();
      run.stats.interrupted = e.interrupted;  // its summary.json says the frames are those done
      LocalizationResult r = resultOf(e, cfg.configs[c], run_name, run, maps[p][c]);
      r.dataset = source->info().name;
      r.labels = pass.labels;
      r.dir = pass.dir / r.dir;
      if (labelers[p]) r.labelling = labelers[p]->stats();
      writeRunFiles(cfg, cfg.configs[c], run, maps[p][c], r, out, pass);
      e.results.push_back(std::move(r));
    }
  }
}

nlohmann::ordered_json toJson(const LocalizationResult& r) {
  const LocalizationSummary& s = r.summary;
  return {{"config", r.config},
          {"descriptor", r.descriptor},
          {"run", r.run},
          {"dataset", r.dataset},
          {"labels", r.labels},
          {"network_pictures", r.labelling.network_runs},
          {"network_share_of_cores", r.labelling.share()},
          {"pictures_with_earlier_labels", r.labelling.reused},
          {"pictures_without_labels", r.labelling.unlabelled},
          {"frames", r.frames},
          {"distance_m", r.distance_m},
          {"n_localizations", s.localizations},
          {"n_error_below_1m", orNull(s.below_1m)},
          {"n_error_below_5m", orNull(s.below_5m)},
          {"mean_translation_error_m", orNull(s.mean_translation_error_m)},
          {"mean_rotation_error_deg", orNull(s.mean_rotation_error_deg)},
          {"n_wrong", r.wrong},
          {"wrong_rate", r.wrong_rate},
          {"recall_along_trajectory", r.recall},
          {"fps", r.hz},
          {"stage_ms", stageMsJson(r.per_frame, false)},
          {"map_segments", r.map_segments},
          {"map_bytes", r.map_bytes},
          {"dir", r.dir.string()},
          {"cumulative", r.cumulative}};
}

// A configuration's name, and where its labels came from when not the simulator's: the legend and
// the table tell the label passes apart.
std::string configText(const LocalizationResult& r) {
  return r.labels.empty() || r.labels == "perfect" ? r.config : r.config + ", " + r.labels;
}

// The paper's accuracy figure: localizations within each error threshold, a panel per query run
// done (an interrupted experiment may not have run them all).
std::vector<viz::Panel> accuracyPanels(const LocalizationExperiment& e) {
  std::vector<viz::Panel> panels;
  for (const std::string& run_name : e.config.query_runs) {
    if (std::none_of(e.results.begin(), e.results.end(),
                     [&](const LocalizationResult& r) { return r.run == run_name; }))
      continue;
    viz::Panel p;
    p.title = run_name;
    p.xlabel = "translation error threshold (m)";
    p.ylabel = "localizations within the threshold";
    p.style = viz::PlotStyle::kSteps;
    p.auto_y = true;
    for (const LocalizationResult& r : e.results) {
      if (r.run != run_name) continue;
      viz::Series s;
      s.name = configText(r);
      s.x = e.thresholds;
      for (size_t v : r.cumulative) s.y.push_back(static_cast<double>(v));
      p.series.push_back(std::move(s));
    }
    panels.push_back(std::move(p));
  }
  return panels;
}

}  // namespace

std::pair<int, int> paperLocalizations(const std::string& run, const std::string& preset) {
  if (preset != "full") return {-1, -1};
  if (run == "S2") return {126, 258};
  if (run == "S3") return {10, 108};
  return {-1, -1};
}

LocalizationExperiment evaluateLocalization(const LocalizationExperimentConfig& cfg,
                                            const std::filesystem::path& out,
                                            const ExperimentProgress& progress) {
  if (cfg.configs.empty())
    throw std::invalid_argument("the localization experiment needs at least one configuration");
  if (cfg.label_passes.empty())
    throw std::invalid_argument("the localization experiment needs at least one label pass");
  LocalizationExperiment e;
  e.config = cfg;
  for (int i = 0; i <= 100; ++i) e.thresholds.push_back(cfg.wrong_m * i / 100.0);
  for (const LabelPass& pass : cfg.label_passes)
    std::filesystem::create_directories(out / pass.dir / "maps");
  // Models load first: a missing one fails before minutes of simulation.
  const PassDescribers describers = passDescribers(cfg);
  const std::vector<std::vector<BuiltMap>> maps = buildMaps(e, describers, out, progress);
  for (const std::string& run_name : cfg.query_runs) {
    if (e.interrupted) break;  // no run starts after the stop request
    localizeRun(e, run_name, describers, maps, out, progress);
  }
  return e;
}

nlohmann::ordered_json toJson(const LocalizationExperiment& e) {
  nlohmann::ordered_json j;
  j["world_seed"] = e.config.world_seed;
  j["preset"] = e.config.preset;
  j["map_run"] = e.config.map_run;
  j["label_noise"] = e.config.label_noise;
  j["label_passes"] = nlohmann::ordered_json::array();
  for (const LabelPass& pass : e.config.label_passes) {
    nlohmann::ordered_json p = {{"labels", pass.labels},
                                {"dir", pass.dir.string()},
                                {"geometric_ground_removal", pass.geometric_ground_removal}};
    if (!pass.descriptor_model.empty())
      p["descriptor"] = {{"kind", pass.descriptor_kind}, {"model", pass.descriptor_model}};
    if (!pass.network.model.empty())
      p["network"] = {{"model", pass.network.model},
                      {"rate_hz", pass.network.rate_hz},
                      {"budget_cores", pass.network.budget_cores},
                      {"latency_s", pass.network.latency_s},
                      {"tolerance_s", pass.network.tolerance_s}};
    j["label_passes"].push_back(std::move(p));
  }
  j["rig"] = e.config.rig;
  j["query_odometry"] = e.config.lidar_odometry ? "lidar" : "simulated";
  j["correct_m"] = e.config.correct_m;
  j["wrong_m"] = e.config.wrong_m;
  j["recall_window_m"] = e.config.recall_window_m;
  j["thresholds_m"] = e.thresholds;
  j["interrupted"] = e.interrupted;  // `results` are the query runs done before Ctrl-C
  j["results"] = nlohmann::ordered_json::array();
  for (const LocalizationResult& r : e.results) j["results"].push_back(toJson(r));
  return j;
}

void writeLocalizationFiles(const LocalizationExperiment& e, const std::filesystem::path& out) {
  std::filesystem::create_directories(out);
  writeJsonAtomically(out / "localization.json", toJson(e));
  if (e.results.empty()) return;  // interrupted while mapping: no run to plot
  viz::plotPanels(out / "localization_accuracy.png",
                  "Localizations against the " + e.config.map_run + " map (world " +
                      std::to_string(e.config.world_seed) + ", " + e.config.preset + ")",
                  accuracyPanels(e));
}

LocalizationExperiment runLocalizationExperiment(const LocalizationExperimentConfig& cfg,
                                                 const std::filesystem::path& out,
                                                 const ExperimentProgress& progress) {
  LocalizationExperiment e = evaluateLocalization(cfg, out, progress);
  writeLocalizationFiles(e, out);
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
                  "| %s | %s | %zu | %s | %s | %zu | %s | %.2f | %.1f | %zu | %.1f | %s |\n",
                  r.run.c_str(), configText(r).c_str(), r.summary.localizations,
                  countText(r.summary.below_1m).c_str(), countText(r.summary.below_5m).c_str(),
                  r.wrong, meanErrorText(r.summary).c_str(), r.recall, r.hz, r.map_segments,
                  static_cast<double>(r.map_bytes) / 1024.0,
                  paper_n >= 0 ? std::to_string(paper_n).c_str() : "-");
    t << line;
  }
  if (e.interrupted) t << partialNote();
  return t.str();
}

}  // namespace semsegmap
