// The saved target map: a versioned little-endian binary file (docs/map-format.md), descriptors
// as float16 by default (about 146 bytes a segment with 64-d descriptors), the settings it was
// built with (TargetMap::parameters), an FNV-1a checksum at the end, written to a temporary name
// and renamed.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "semsegmap/localize/target_map.h"

namespace semsegmap {

// 2: the settings the map was built with follow the header (version 1 had none).
constexpr uint32_t kMapFormatVersion = 2;

struct MapWriteOptions {
  bool float16 = true;  // halves the size; retrieval ranks are unchanged in practice
};

// Returns the number of bytes written. Throws std::runtime_error naming `path` on failure.
uint64_t saveTargetMap(const std::filesystem::path& path, const TargetMap& map,
                       const MapWriteOptions& options = {});
// Throws std::runtime_error "<path>: <what is wrong>" for a missing, truncated or corrupt file,
// one of another format version, or one holding a non-finite centroid, descriptor or point.
TargetMap loadTargetMap(const std::filesystem::path& path);

}  // namespace semsegmap
