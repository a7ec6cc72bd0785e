#include "eval_args.h"

#include <filesystem>
#include <sstream>

#include "resources.h"

namespace semsegmap::app {

std::vector<std::string> splitList(const std::string& s, char separator) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, separator))
    if (!item.empty()) out.push_back(item);
  return out;
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
