#include "semsegmap/eval/descriptor_experiment.h"

#include <cstdio>
#include <memory>
#include <sstream>

#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/datasets/dataset_specs.h"
#include "semsegmap/viz/plot.h"

namespace semsegmap {

namespace {

// One panel per completeness band, one curve per descriptor: the paper's retrieval figure.
std::vector<viz::Panel> retrievalPanels(const DescriptorExperiment& e) {
  std::vector<viz::Panel> panels(e.bands.size());
  for (size_t b = 0; b < e.bands.size(); ++b) {
    panels[b].title = "completeness " + e.bands[b].name;
    panels[b].xlabel = "k (nearest target descriptors)";
    panels[b].ylabel = "fraction of true matches within k";
    panels[b].log_x = true;
    for (const DescriptorRetrieval& r : e.results) {
      viz::Series series;
      series.name = r.descriptor;
      for (int k = 0; k < e.config.max_k; ++k) {
        series.x.push_back(k + 1);
        series.y.push_back(r.band_curves[b][static_cast<size_t>(k)]);
      }
      panels[b].series.push_back(std::move(series));
    }
  }
  return panels;
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
  const TrainingSet set = extractTrainingSet({e.dataset}, cfg.segmentation.config, extraction,
                                             [&](size_t done, size_t total, size_t) {
                                               if (progress)
                                                 progress("segment " + cfg.run, done, total);
                                             });
  const RetrievalQueries q = makeRetrievalQueries(set);
  e.segments = q.targets.size();
  e.queries = q.queries.size();
  e.bands = defaultCompletenessBands();
  e.interrupted = set.interrupted;
  for (size_t d = 0; d < describers.size() && !e.interrupted; ++d) {
    if (progress) progress("describe", d, describers.size());
    if ((e.interrupted = cfg.stop.stopRequested())) break;
    e.results.push_back(evaluateRetrieval(*describers[d], set, q, e.bands, cfg.max_k));
  }
  if (progress) progress("describe", e.results.size(), describers.size());
  return e;
}

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
                                {"band_curves", r.band_curves}});
  return j;
}

void writeDescriptorFiles(const DescriptorExperiment& e, const std::filesystem::path& out) {
  std::filesystem::create_directories(out);
  writeJsonAtomically(out / "descriptors.json", toJson(e));
  viz::plotPanels(out / "descriptors.png",
                  "Descriptor retrieval on " + e.dataset + " (" + std::to_string(e.queries) +
                      " partial observations of " + std::to_string(e.segments) + " segments)",
                  retrievalPanels(e));
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
      const auto& curve = r.band_curves[b];
      const double top16 = curve.empty() ? 0.0 : curve[std::min<size_t>(15, curve.size() - 1)];
      std::snprintf(v, sizeof(v), " %.3f |", top16);
      t << v;
    }
    std::snprintf(v, sizeof(v), " %.0f |\n", r.segments_per_second);
    t << v;
  }
  if (e.interrupted) t << partialNote();
  return t.str();
}

}  // namespace semsegmap
