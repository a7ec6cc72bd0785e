// The enriched cloud as a PLY file, to look at in any point-cloud viewer (CloudCompare,
// MeshLab, Open3D) with its camera colours and classes.
#pragma once

#include <cstdint>
#include <filesystem>

#include "semsegmap/core/enriched_point.h"

namespace semsegmap {

// Binary little-endian PLY, one vertex per point in cloud order:
//   x y z (float), red green blue (uchar, the HSV turned back into RGB; 0 without colour),
//   class (ushort, ids of the class table), has_color (uchar 0/1).
// Written atomically (temporary name + rename); throws std::runtime_error naming the file.
void writeEnrichedPly(const std::filesystem::path& path, const EnrichedCloud& cloud);

// Inverse of rgbToHsv (enrich/): hue in [0, 1) (cyclic), s and v in [0, 1], rounded to 8 bits;
// exact for colours that came from 8-bit RGB.
void hsvToRgb(float h, float s, float v, uint8_t& r, uint8_t& g, uint8_t& b);

}  // namespace semsegmap
