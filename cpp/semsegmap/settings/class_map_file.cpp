#include "semsegmap/settings/class_map_file.h"

#include "semsegmap/io/yaml_fields.h"

namespace semsegmap {

ClassMap readClassMap(const std::filesystem::path& path, const ClassTable& classes) {
  const YAML::Node root = loadYamlFile(path);
  const YamlFields f(path);
  f.expectMap(root, "the top level");
  f.checkKeys(root, "", {"name", "classes"});
  const std::string name = f.text(root, "", "name");
  const YAML::Node list = f.child(root, "", "classes");
  if (!list.IsSequence() || list.size() == 0)
    f.fail("classes: expected a list of {id, name, class}, got " + YamlFields::describe(list));
  std::vector<ClassMapEntry> entries;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string where = "classes[" + std::to_string(i) + "]";
    f.expectMap(list[i], where);
    f.checkKeys(list[i], where, {"id", "name", "class"});
    ClassMapEntry e;
    e.source_id = static_cast<int>(f.integer(list[i], where, "id", 0, 65535));
    e.source_name = f.text(list[i], where, "name");
    const std::string target = f.text(list[i], where, "class");
    const std::optional<ClassId> id = classes.find(target);
    if (!id) f.fail(where + ".class: '" + target + "' is not a class of the class table");
    e.target = *id;
    entries.push_back(e);
  }
  try {
    return ClassMap(name, std::move(entries));
  } catch (const std::invalid_argument& e) {
    f.fail(e.what());
  }
}

ClassMap resolveClassMap(const std::string& name_or_file, const std::filesystem::path& base_dir,
                         const std::filesystem::path& shipped_dir, const ClassTable& classes) {
  if (name_or_file == "semsegmap") return ClassMap::Identity(classes);
  const std::filesystem::path as_path(name_or_file);
  const bool is_name = !as_path.has_parent_path() && as_path.extension() != ".yaml";
  if (!is_name) return readClassMap(as_path.is_absolute() ? as_path : base_dir / as_path, classes);
  const std::filesystem::path shipped = shipped_dir / (name_or_file + ".yaml");
  if (shipped_dir.empty() || !std::filesystem::exists(shipped))
    throw std::runtime_error("class map '" + name_or_file + "': not a shipped class map (" +
                             shipped.string() + " does not exist); give a YAML file instead");
  return readClassMap(shipped, classes);
}

}  // namespace semsegmap
