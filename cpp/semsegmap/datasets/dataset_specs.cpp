#include "semsegmap/datasets/dataset_specs.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "semsegmap/datasets/open_dataset.h"

namespace semsegmap {

TrainingSet extractTrainingSet(const std::vector<std::string>& specs,
                               const PipelineConfig& pipeline, const ExtractionConfig& config,
                               const ExtractionProgress& progress, const DatasetOptions& options) {
  if (specs.empty()) throw std::invalid_argument("no dataset to extract training data from");
  if (specs.size() > 0xffff) throw std::invalid_argument("too many datasets (at most 65535)");
  TrainingSet set;
  set.sources = specs;
  for (const auto& spec : specs) set.source_worlds.push_back(worldOf(spec));
  for (size_t i = 0; i < specs.size() && !set.interrupted; ++i) {
    auto source = openDataset(specs[i], options);
    appendObservations(*source, static_cast<uint16_t>(i), pipeline, config, set, progress);
  }
  return set;
}

std::string worldOf(const std::string& spec) {
  if (spec.rfind("sim:", 0) != 0) return spec;
  // The defaults of openDataset: world 1, the full preset.
  std::string world = "1", preset = "full";
  std::stringstream ss(spec.substr(4));
  std::string item;
  while (std::getline(ss, item, ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos) continue;
    if (item.substr(0, eq) == "world") world = item.substr(eq + 1);
    if (item.substr(0, eq) == "preset") preset = item.substr(eq + 1);
  }
  return "sim:world=" + world + ",preset=" + preset;
}

std::vector<std::string> splitDatasetSpecs(const std::string& list) {
  auto isSimKey = [](const std::string& token) {
    const auto eq = token.find('=');
    return eq != std::string::npos && eq > 0 && token.find_first_of("/:") == std::string::npos;
  };
  std::vector<std::string> specs;
  size_t start = 0;
  while (start <= list.size()) {
    const size_t end = std::min(list.find(';', start), list.size());
    const std::string group = list.substr(start, end - start);
    bool in_sim = false;
    size_t token_start = 0;
    while (token_start <= group.size()) {
      const size_t token_end = std::min(group.find(',', token_start), group.size());
      const std::string token = group.substr(token_start, token_end - token_start);
      if (in_sim && isSimKey(token)) {
        specs.back() += "," + token;
      } else {
        if (token.empty())
          throw std::invalid_argument("dataset list '" + list + "': empty dataset spec");
        specs.push_back(token);
        in_sim = token.rfind("sim:", 0) == 0;
      }
      token_start = token_end + 1;
    }
    start = end + 1;
  }
  return specs;
}

}  // namespace semsegmap
