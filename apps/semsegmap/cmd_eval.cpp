// semsegmap eval <experiment>: the paper's experiments as commands. So far: descriptors.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "cli_args.h"
#include "progress.h"
#include "semsegmap/eval/descriptor_eval.h"
#include "semsegmap/io/atomic_file.h"
#include "semsegmap/io/config.h"
#include "semsegmap/viz/plot.h"

namespace semsegmap::app {

namespace {

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

int runEvalDescriptors(const std::vector<std::string>& args) {
  const CliArgs a(args,
                  {"world-seed", "out", "preset", "run", "max-frames", "config", "models",
                   "descriptors", "threads"},
                  {});
  const std::filesystem::path out = a.require("out");
  const std::string spec = "sim:world=" + std::to_string(a.getInt("world-seed", 1)) +
                           ",run=" + a.get("run", "S0") + ",preset=" + a.get("preset", "full");
  const PipelineConfig pipeline = loadPipelineConfig(a.get("config", "config/semsegmap.yaml"));
  const std::filesystem::path models = a.get("models", "models");
  std::vector<DescriptorKind> kinds;
  for (const auto& name : splitList(a.get("descriptors", "semsegmap-net,segmap-cnn,fpfh,eigen")))
    kinds.push_back(parseDescriptorKind(name));
  DescriberOptions options;
  options.threads = static_cast<int>(a.getInt("threads", 0));
  // Load every model first: a missing one should fail before minutes of simulation.
  std::vector<std::unique_ptr<Describer>> describers;
  for (DescriptorKind kind : kinds) {
    options.model_path = (models / (descriptorName(kind) + ".model")).string();
    describers.push_back(makeDescriber(kind, options));
  }

  ExtractionConfig extraction;
  extraction.max_frames = static_cast<size_t>(std::max<long long>(0, a.getInt("max-frames", 0)));
  extraction.min_purity = 0.0f;  // every segment counts, as it would in a target map
  std::unique_ptr<Progress> progress;
  const TrainingSet set =
      extractTrainingSet({spec}, pipeline, extraction, [&](size_t done, size_t total, size_t) {
        if (!progress) progress = std::make_unique<Progress>("segment " + spec, total);
        progress->update(done);
      });
  const RetrievalQueries q = makeRetrievalQueries(set);
  std::printf("%zu segments with %zu earlier observations\n", q.targets.size(), q.queries.size());

  const auto bands = defaultCompletenessBands();
  const int max_k = 50;
  std::ostringstream json;
  json << "{\n  \"dataset\": \"" << spec << "\",\n  \"segments\": " << q.targets.size()
       << ",\n  \"queries\": " << q.queries.size() << ",\n  \"bands\": [";
  for (size_t b = 0; b < bands.size(); ++b)
    json << (b ? ", " : "") << "\"" << bands[b].name << "\"";
  json << "],\n  \"descriptors\": [\n";
  std::printf("%-14s %7s %7s  %s\n", "descriptor", "top-1", "top-16", "segments/s");
  // One panel per completeness band, one curve per descriptor: the paper's retrieval figure.
  std::vector<viz::Panel> panels(bands.size());
  for (size_t b = 0; b < bands.size(); ++b) {
    panels[b].title = "completeness " + bands[b].name;
    panels[b].xlabel = "k (nearest target descriptors)";
    panels[b].ylabel = "fraction of true matches within k";
    panels[b].log_x = true;
  }
  for (size_t d = 0; d < describers.size(); ++d) {
    const DescriptorRetrieval r = evaluateRetrieval(*describers[d], set, q, bands, max_k);
    for (size_t b = 0; b < bands.size(); ++b) {
      viz::Series series{r.descriptor, {}, {}};
      for (int k = 0; k < max_k; ++k) {
        series.x.push_back(k + 1);
        series.y.push_back(r.band_curves[b][static_cast<size_t>(k)]);
      }
      panels[b].series.push_back(std::move(series));
    }
    std::printf("%-14s %7.3f %7.3f  %.0f\n", r.descriptor.c_str(), r.top1, r.top16,
                r.segments_per_second);
    json << "    {\"name\": \"" << r.descriptor << "\", \"top1\": " << r.top1
         << ", \"top16\": " << r.top16 << ", \"segments_per_second\": " << r.segments_per_second
         << ", \"band_counts\": [";
    for (size_t b = 0; b < bands.size(); ++b) json << (b ? ", " : "") << r.band_counts[b];
    json << "], \"band_curves\": [";
    for (size_t b = 0; b < bands.size(); ++b) {
      json << (b ? ", " : "") << "[";
      for (int k = 0; k < max_k; ++k) json << (k ? ", " : "") << r.band_curves[b][k];
      json << "]";
    }
    json << "]}" << (d + 1 < describers.size() ? "," : "") << "\n";
  }
  json << "  ]\n}\n";
  std::filesystem::create_directories(out);
  writeBytesAtomically(out / "descriptors.json", json.str());
  viz::plotPanels(out / "descriptors.png",
                  "Descriptor retrieval on " + spec + " (" + std::to_string(q.queries.size()) +
                      " partial observations of " + std::to_string(q.targets.size()) + " segments)",
                  panels);
  std::cout << "wrote " << (out / "descriptors.json").string() << ", descriptors.png\n";
  return 0;
}

}  // namespace

int runEval(const std::vector<std::string>& args) {
  if (args.empty()) throw std::invalid_argument("eval needs an experiment: descriptors");
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (args[0] == "descriptors") return runEvalDescriptors(rest);
  throw std::invalid_argument("unknown experiment '" + args[0] + "' (expected descriptors)");
}

}  // namespace semsegmap::app
