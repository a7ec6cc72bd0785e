#include "semsegmap/io/yaml_fields.h"

#include <limits>
#include <stdexcept>

namespace semsegmap {

YAML::Node loadYamlFile(const std::filesystem::path& path) {
  const YamlFields p(path);
  if (!std::filesystem::exists(path)) p.fail("missing");
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    p.fail("is a directory or a device, not a YAML file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::ParserException& e) {
    p.fail("YAML syntax error at line " + std::to_string(e.mark.line + 1) + ", column " +
           std::to_string(e.mark.column + 1) + ": " + e.msg);
  } catch (const std::exception& e) {  // yaml-cpp's and the stream's own errors
    p.fail(std::string("cannot read: ") + e.what());
  }
  if (!root.IsMap()) p.fail("expected a YAML mapping at the top level");
  return root;
}

void readOptionalLidarModel(const YamlFields& p, const YAML::Node& node, const std::string& w,
                            LidarModel& lidar) {
  auto integer = [&](const char* key, int& value) {
    if (node[key])
      value = static_cast<int>(p.integer(node, w, key, 1, std::numeric_limits<int>::max()));
  };
  auto number = [&](const char* key, double& value) {
    if (node[key]) value = p.number(node, w, key);
  };
  integer("columns", lidar.columns);
  integer("rows", lidar.rows);
  number("hfov_deg", lidar.hfov_deg);
  number("vfov_up_deg", lidar.vfov_up_deg);
  number("vfov_down_deg", lidar.vfov_down_deg);
  number("min_range_m", lidar.min_range_m);
  number("max_range_m", lidar.max_range_m);
  number("range_noise_m", lidar.range_noise_m);
  number("dropout", lidar.dropout);
}

}  // namespace semsegmap
