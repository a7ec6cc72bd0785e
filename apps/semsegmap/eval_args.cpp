#include "eval_args.h"

#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "resources.h"
#include "semsegmap/settings/config.h"

namespace semsegmap::app {

std::vector<std::string> splitList(const std::string& s, char separator) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, separator))
    if (!item.empty()) out.push_back(item);
  return out;
}

// One pass of --labels: perfect | network[,rate=R][,budget=C][,every][,ground=G][,config=FILE]:
// the simulator's labels, or the shipped segmentation network's (config/semantics-sim-network.yaml,
// or FILE's semantics: section) at its shipped budget, at R pictures a second per camera, within
// C cores, or on every picture; the ground removed as the file's local_map section says, or by
// class alone (ground=classes) or by geometry as well (ground=geometry); SemSegMap described
// with the file's descriptor.model (trained on the network's labels), or with each
// configuration's own (descriptor=own).
LabelPass labelPass(const std::string& spec) {
  LabelPass pass;
  pass.labels = spec;
  if (spec == "perfect") return pass;
  const std::vector<std::string> keys = splitList(spec);
  if (keys.empty() || keys.front() != "network")
    throw UsageError(
        "--labels expects perfect or network[,rate=R][,budget=C][,every][,ground=G]"
        "[,descriptor=own][,config=FILE], joined by +, got '" +
        spec + "'");
  std::filesystem::path file = shippedFile("config/semantics-sim-network.yaml");
  for (size_t i = 1; i < keys.size(); ++i)
    if (keys[i].rfind("config=", 0) == 0) file = keys[i].substr(7);
  SemanticsConfig& n = pass.network;
  n = loadSemanticsConfig(file);
  const Settings settings = loadSettings(file);
  pass.geometric_ground_removal = settings.local_map.geometric_ground_removal;
  if (!settings.descriptor.model.empty()) {
    pass.descriptor_kind = settings.descriptor.kind;
    pass.descriptor_model = settings.descriptor.model;
  }
  for (size_t i = 1; i < keys.size(); ++i) {
    const std::string& k = keys[i];
    const auto number = [&](size_t at) {
      char* end = nullptr;
      const double v = std::strtod(k.c_str() + at, &end);
      if (end == k.c_str() + at || *end != '\0' || !(v > 0))
        throw UsageError("--labels: " + k + " needs a positive number");
      return v;
    };
    if (k.rfind("rate=", 0) == 0) {
      n.rate_hz = number(5);
      n.budget_cores = 0;  // the rate alone limits the network
    } else if (k.rfind("budget=", 0) == 0) {
      n.budget_cores = number(7);
    } else if (k == "every") {
      n.rate_hz = n.budget_cores = n.latency_s = 0;
    } else if (k == "ground=classes" || k == "ground=geometry") {
      pass.geometric_ground_removal = k == "ground=geometry";
    } else if (k == "descriptor=own") {
      pass.descriptor_kind.clear();
      pass.descriptor_model.clear();
    } else if (k.rfind("config=", 0) != 0) {
      throw UsageError("--labels: unknown key '" + k +
                       "' (rate=R, budget=C, every, ground=classes|geometry, descriptor=own, "
                       "config=FILE)");
    }
  }
  checkReplayable(n, file.string());
  return pass;
}

std::vector<NamedConfig> comparedConfigs(const CliArgs& a) {
  std::vector<NamedConfig> configs;
  for (const std::string& name : splitList(a.get("configs"))) {
    const std::filesystem::path path =
        a.has("configs") ? std::filesystem::path(name) : shippedFile(name);
    configs.push_back(loadNamedConfig(path));
  }
  return configs;
}

}  // namespace semsegmap::app
