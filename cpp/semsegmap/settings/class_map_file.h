// Class map files (docs/class-maps.md): a network's or another tool's class ids -> the project's
// classes. Shipped: config/class_maps/cityscapes.yaml (the 19 training ids), cityscapes-ids.yaml
// (the 34 label ids of Cityscapes' *_labelIds.png) and ade20k.yaml (150 classes).
#pragma once

#include <filesystem>
#include <string>

#include "semsegmap/core/class_table.h"
#include "semsegmap/semantics/class_map.h"

namespace semsegmap {

// Reads a class map whose targets are classes of `classes` (by name). Throws std::runtime_error
// "<file>: <field>: <what was wrong>" for a missing file, an unknown key or target class, an id
// listed twice.
ClassMap readClassMap(const std::filesystem::path& path, const ClassTable& classes);

// A class map's name or file as written in a config or label set: "semsegmap" (the project's
// own ids), a shipped map's name (a file <name>.yaml in `shipped_dir`) or a path, relative to
// `base_dir`. Throws naming what it looked for.
ClassMap resolveClassMap(const std::string& name_or_file, const std::filesystem::path& base_dir,
                         const std::filesystem::path& shipped_dir, const ClassTable& classes);

}  // namespace semsegmap
