#include "semsegmap/io/label_set.h"

#include <cstdio>
#include <sstream>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/io/yaml_fields.h"

namespace semsegmap {

void writeLabelSetInfo(const std::filesystem::path& dir, const LabelSetInfo& info) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "class_map" << YAML::Value << info.class_map;
  out << YAML::Key << "frames" << YAML::Value << info.frames;
  if (info.dataset_frames > 0)
    out << YAML::Key << "dataset_frames" << YAML::Value << info.dataset_frames;
  out << YAML::Key << "cameras" << YAML::Value << info.cameras;
  out << YAML::Key << "dataset" << YAML::Value << info.dataset;
  out << YAML::Key << "model" << YAML::Value << info.model;
  if (info.interrupted) out << YAML::Key << "interrupted" << YAML::Value << true;
  out << YAML::EndMap;
  writeBytesAtomically(dir / "labels.yaml", std::string(out.c_str()) + "\n");
}

LabelSetInfo readLabelSetInfo(const std::filesystem::path& dir) {
  const std::filesystem::path path = dir / "labels.yaml";
  if (!std::filesystem::is_directory(dir))
    throw std::runtime_error(dir.string() + ": no such label set directory");
  if (!std::filesystem::exists(path))
    throw std::runtime_error(path.string() +
                             ": missing: a label set says what its ids mean (class_map: "
                             "semsegmap, cityscapes, ade20k or a class map file)");
  const YAML::Node root = loadYamlFile(path);
  const YamlFields f(path);
  f.expectMap(root, "the top level");
  f.checkKeys(
      root, "",
      {"class_map", "frames", "dataset_frames", "cameras", "dataset", "model", "interrupted"});
  LabelSetInfo info;
  info.class_map = f.text(root, "", "class_map");
  info.frames = static_cast<size_t>(f.integer(root, "", "frames", 1, 1LL << 40));
  if (root["dataset_frames"])
    info.dataset_frames = static_cast<size_t>(f.integer(root, "", "dataset_frames", 1, 1LL << 40));
  info.cameras = static_cast<size_t>(f.integer(root, "", "cameras", 1, 64));
  if (root["dataset"]) info.dataset = f.text(root, "", "dataset");
  if (root["model"]) info.model = f.text(root, "", "model");
  if (root["interrupted"]) info.interrupted = f.flag(root, "", "interrupted");
  return info;
}

std::filesystem::path labelSetImage(const std::filesystem::path& dir, size_t camera, size_t frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06zu.png", frame);
  return dir / ("cam" + std::to_string(camera)) / name;
}

}  // namespace semsegmap
