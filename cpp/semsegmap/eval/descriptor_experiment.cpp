#include "semsegmap/eval/descriptor_experiment.h"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <memory>
#include <sstream>

#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/frame_subset.h"
#include "semsegmap/datasets/dataset_specs.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/viz/plot.h"

namespace semsegmap {

namespace {

// The curve's 16th entry: within k = 16 (or the last k asked for).
double top16Of(const std::vector<double>& curve) {
  return curve.empty() ? 0.0 : curve[std::min<size_t>(15, curve.size() - 1)];
}

// A panel of retrieval curves, one per descriptor: `curve` picks each one's.
viz::Panel retrievalPanel(
    const DescriptorExperiment& e, const std::string& title,
    const std::vector<DescriptorRetrieval>& results,
    const std::function<const std::vector<double>&(const DescriptorRetrieval&)>& curve) {
  viz::Panel panel;
  panel.title = title;
  panel.xlabel = "k (nearest target descriptors)";
  panel.ylabel = "fraction of true matches within k";
  panel.log_x = true;
  for (const DescriptorRetrieval& r : results) {
    viz::Series series;
    series.name = r.descriptor;
    const std::vector<double>& c = curve(r);
    for (int k = 0; k < e.config.max_k && k < static_cast<int>(c.size()); ++k) {
      series.x.push_back(k + 1);
      series.y.push_back(c[static_cast<size_t>(k)]);
    }
    panel.series.push_back(std::move(series));
  }
  return panel;
}

// One panel per completeness band, one curve per descriptor; `curves` picks the binning (true:
// the paper's retrieval figure, or estimated).
std::vector<viz::Panel> bandPanels(const DescriptorExperiment& e, const std::string& prefix,
                                   std::vector<std::vector<double>> DescriptorRetrieval::*curves) {
  std::vector<viz::Panel> panels;
  for (size_t b = 0; b < e.bands.size(); ++b)
    panels.push_back(retrievalPanel(
        e, prefix + e.bands[b].name, e.results,
        [ b, curves ](const DescriptorRetrieval& r) -> const auto& { return (r.*curves)[b]; }));
  return panels;
}

// The same per band of the run-time estimate, and the one-scan wake-ups' whole curve.
std::vector<viz::Panel> estimatedPanels(const DescriptorExperiment& e) {
  std::vector<viz::Panel> panels =
      bandPanels(e, "estimated ", &DescriptorRetrieval::estimated_band_curves);
  if (!e.wake_up_results.empty())
    panels.push_back(retrievalPanel(
        e, "one-scan wake-ups", e.wake_up_results,
        [](const DescriptorRetrieval& r) -> const auto& { return r.all_curve; }));
  return panels;
}

// A source per wake-up: a pipeline started empty segments that one scan, as a robot waking up
// does before it relocalizes (localize/relocalizer.h).
size_t appendWakeUps(const DescriptorExperimentConfig& cfg, const std::string& spec,
                     const ExtractionConfig& extraction, TrainingSet& set,
                     const ExperimentProgress& progress) {
  auto source = openDataset(spec);
  const size_t n = framesToRead(*source, cfg.max_frames);
  size_t wake_ups = 0;
  for (size_t f = 0; f < n && !extraction.stop.stopRequested(); f += cfg.wake_up_every) {
    if (set.sources.size() >= 0xffff) break;
    const auto index = static_cast<uint16_t>(set.sources.size());
    set.sources.push_back(spec + " frame " + std::to_string(f));
    set.source_worlds.push_back(worldOf(spec));
    FrameSubset one(*source, {f});
    appendObservations(one, index, cfg.segmentation.config, extraction, set);
    ++wake_ups;
    if (progress) progress("wake up on " + cfg.wake_up_run, f + 1, n);
  }
  return wake_ups;
}

// The estimate's agreement for every window asked for; the queries keep the configured one's.
void estimateCompleteness(const DescriptorExperimentConfig& cfg, const TrainingSet& set,
                          RetrievalQueries& q, DescriptorExperiment& e) {
  std::vector<size_t> windows = cfg.completeness_windows;
  std::vector<double> chosen;
  windows.push_back(cfg.completeness_window);
  std::sort(windows.begin(), windows.end());
  windows.erase(std::unique(windows.begin(), windows.end()), windows.end());
  for (size_t w : windows) {
    const std::vector<double> all = estimatedCompleteness(set, w);
    q.estimated.clear();
    for (size_t i : q.queries) q.estimated.push_back(all[i]);
    e.windows.push_back(completenessAgreement(q, e.bands, w));
    if (w == cfg.completeness_window) {
      e.agreement = e.windows.back();
      chosen = q.estimated;
    }
  }
  q.estimated = chosen;
}

}  // namespace

DescriptorExperiment evaluateDescriptors(const DescriptorExperimentConfig& cfg,
                                         const ExperimentProgress& progress) {
  DescriptorExperiment e;
  e.config = cfg;
  e.dataset = simulatedRunSpec(cfg.world_seed, cfg.run, cfg.preset);
  // Load every model first: a missing one should fail before minutes of simulation.
  std::vector<std::unique_ptr<Describer>> describers;
  for (const std::string& name : cfg.descriptors) {
    DescriptorConfig descriptor;
    descriptor.kind = name;
    descriptor.model = (cfg.models / (name + ".model")).string();  // read by the learned kinds
    describers.push_back(makeDescriber(descriptor, cfg.threads));
  }

  ExtractionConfig extraction;
  extraction.max_frames = cfg.max_frames;
  extraction.min_purity = 0.0f;  // every segment counts, as it would in a target map
  extraction.stop = cfg.stop;
  TrainingSet set = extractTrainingSet({e.dataset}, cfg.segmentation.config, extraction,
                                       [&](size_t done, size_t total, size_t) {
                                         if (progress) progress("segment " + cfg.run, done, total);
                                       });
  e.bands = defaultCompletenessBands();
  RetrievalQueries q = makeRetrievalQueries(set);
  e.segments = q.targets.size();
  e.queries = q.queries.size();
  estimateCompleteness(cfg, set, q, e);
  if (cfg.wake_up_every > 0 && !set.interrupted) {
    e.wake_up_dataset = simulatedRunSpec(cfg.world_seed, cfg.wake_up_run, cfg.preset);
    e.wake_ups = appendWakeUps(cfg, e.wake_up_dataset, extraction, set, progress);
  }
  const RetrievalQueries wake = makeWakeUpQueries(set, q.targets, 1);
  e.wake_up_queries = wake.queries.size();
  e.interrupted = set.interrupted || cfg.stop.stopRequested();
  for (size_t d = 0; d < describers.size() && !e.interrupted; ++d) {
    if (progress) progress("describe", d, describers.size());
    if ((e.interrupted = cfg.stop.stopRequested())) break;
    e.results.push_back(evaluateRetrieval(*describers[d], set, q, e.bands, cfg.max_k));
    if (!wake.queries.empty())
      e.wake_up_results.push_back(evaluateRetrieval(*describers[d], set, wake, e.bands, cfg.max_k));
  }
  if (progress) progress("describe", e.results.size(), describers.size());
  return e;
}

namespace {

nlohmann::ordered_json toJson(const CompletenessAgreement& a) {
  return {{"window_frames", a.window_frames},
          {"spearman", a.spearman},
          {"same_band", a.same_band},
          {"confusion", a.confusion}};
}

nlohmann::ordered_json wakeUpJson(const DescriptorExperiment& e) {
  nlohmann::ordered_json j{{"dataset", e.wake_up_dataset},
                           {"every_frames", e.config.wake_up_every},
                           {"wake_ups", e.wake_ups},
                           {"queries", e.wake_up_queries}};
  j["descriptors"] = nlohmann::ordered_json::array();
  for (const DescriptorRetrieval& r : e.wake_up_results)
    j["descriptors"].push_back({{"name", r.descriptor},
                                {"top1", r.top1},
                                {"top16", r.top16},
                                {"band_counts", r.band_counts},
                                {"band_curves", r.band_curves}});
  return j;
}

}  // namespace

nlohmann::ordered_json toJson(const DescriptorExperiment& e) {
  nlohmann::ordered_json j;
  j["dataset"] = e.dataset;
  j["segments"] = e.segments;
  j["queries"] = e.queries;
  j["interrupted"] = e.interrupted;  // of the frames and descriptors done before Ctrl-C
  j["bands"] = nlohmann::ordered_json::array();
  for (const CompletenessBand& b : e.bands) j["bands"].push_back(b.name);
  j["descriptors"] = nlohmann::ordered_json::array();
  for (const DescriptorRetrieval& r : e.results)
    j["descriptors"].push_back({{"name", r.descriptor},
                                {"top1", r.top1},
                                {"top16", r.top16},
                                {"segments_per_second", r.segments_per_second},
                                {"band_counts", r.band_counts},
                                {"band_curves", r.band_curves},
                                {"estimated_band_counts", r.estimated_band_counts},
                                {"estimated_band_curves", r.estimated_band_curves}});
  j["completeness_estimate"] = {{"window_frames", e.config.completeness_window},
                                {"agreement", toJson(e.agreement)}};
  j["completeness_estimate"]["windows"] = nlohmann::ordered_json::array();
  for (const CompletenessAgreement& a : e.windows)
    j["completeness_estimate"]["windows"].push_back(toJson(a));
  j["wake_ups"] = wakeUpJson(e);
  return j;
}

void writeDescriptorFiles(const DescriptorExperiment& e, const std::filesystem::path& out) {
  std::filesystem::create_directories(out);
  writeJsonAtomically(out / "descriptors.json", toJson(e));
  viz::plotPanels(out / "descriptors.png",
                  "Descriptor retrieval on " + e.dataset + " (" + std::to_string(e.queries) +
                      " partial observations of " + std::to_string(e.segments) + " segments)",
                  bandPanels(e, "completeness ", &DescriptorRetrieval::band_curves));
  if (e.results.empty() || e.results.front().estimated_band_curves.empty()) return;
  viz::plotPanels(out / "completeness.png",
                  "Retrieval by run-time completeness estimate (" +
                      std::to_string(e.config.completeness_window) + "-frame window) on " +
                      e.dataset + ", and on " + std::to_string(e.wake_ups) +
                      " one-scan wake-ups on " + e.wake_up_dataset,
                  estimatedPanels(e));
}

DescriptorExperiment runDescriptorExperiment(const DescriptorExperimentConfig& cfg,
                                             const std::filesystem::path& out,
                                             const ExperimentProgress& progress) {
  DescriptorExperiment e = evaluateDescriptors(cfg, progress);
  writeDescriptorFiles(e, out);
  return e;
}

std::string descriptorTable(const DescriptorExperiment& e) {
  std::ostringstream t;
  t << "| descriptor | top-1 | top-16 |";
  for (const CompletenessBand& b : e.bands) t << " top-16 " << b.name << " |";
  t << " segments/s |\n| --- | ---: | ---: |";
  for (size_t b = 0; b < e.bands.size(); ++b) t << " ---: |";
  t << " ---: |\n";
  char v[64];
  for (const DescriptorRetrieval& r : e.results) {
    std::snprintf(v, sizeof(v), "| %s | %.3f | %.3f |", r.descriptor.c_str(), r.top1, r.top16);
    t << v;
    for (size_t b = 0; b < e.bands.size(); ++b) {
      // The curve's 16th entry: within k = 16 (or the last k asked for).
      std::snprintf(v, sizeof(v), " %.3f |", top16Of(r.band_curves[b]));
      t << v;
    }
    std::snprintf(v, sizeof(v), " %.0f |\n", r.segments_per_second);
    t << v;
  }
  if (e.interrupted) t << partialNote();
  return t.str();
}

std::string completenessTable(const DescriptorExperiment& e) {
  std::ostringstream t;
  char v[96];
  t << "| window (frames) | Spearman | same band |\n| ---: | ---: | ---: |\n";
  for (const CompletenessAgreement& a : e.windows) {
    std::snprintf(v, sizeof(v), "| %zu%s | %.3f | %.3f |\n", a.window_frames,
                  a.window_frames == e.config.completeness_window ? " (used)" : "", a.spearman,
                  a.same_band);
    t << v;
  }
  t << "\n| descriptor |";
  for (const CompletenessBand& b : e.bands) t << " top-16 estimated " << b.name << " |";
  t << " wake-ups top-1 | wake-ups top-16 |\n| --- |";
  for (size_t b = 0; b < e.bands.size() + 2; ++b) t << " ---: |";
  t << "\n";
  for (size_t d = 0; d < e.results.size(); ++d) {
    const DescriptorRetrieval& r = e.results[d];
    t << "| " << r.descriptor << " |";
    for (const auto& curve : r.estimated_band_curves) {
      std::snprintf(v, sizeof(v), " %.3f |", top16Of(curve));
      t << v;
    }
    if (d < e.wake_up_results.size())
      std::snprintf(v, sizeof(v), " %.3f | %.3f |\n", e.wake_up_results[d].top1,
                    e.wake_up_results[d].top16);
    else
      std::snprintf(v, sizeof(v), " - | - |\n");
    t << v;
  }
  return t.str();
}

}  // namespace semsegmap
