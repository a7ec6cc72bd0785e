#include "semsegmap/io/ply_writer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "semsegmap/core/atomic_file.h"

namespace semsegmap {

namespace {

// Byte by byte, so the file is little-endian whatever the host's byte order.
void putLe(std::string& out, uint32_t bits, int bytes) {
  for (int k = 0; k < bytes; ++k) out.push_back(static_cast<char>((bits >> (8 * k)) & 0xff));
}

void putFloat(std::string& out, float f) {
  uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof bits);
  putLe(out, bits, 4);
}

uint8_t toByte(float x) {
  return static_cast<uint8_t>(std::lround(std::clamp(x, 0.0f, 1.0f) * 255.0f));
}

}  // namespace

void hsvToRgb(float h, float s, float v, uint8_t& r, uint8_t& g, uint8_t& b) {
  const float h6 = (h - std::floor(h)) * 6.0f;  // cyclic hue in sixths, [0, 6]
  const float c = v * s;
  const float x = c * (1.0f - std::fabs(std::fmod(h6, 2.0f) - 1.0f));
  const float m = v - c;
  float rf = 0, gf = 0, bf = 0;
  switch (std::min(static_cast<int>(h6), 5)) {
    case 0:
      rf = c, gf = x;
      break;
    case 1:
      rf = x, gf = c;
      break;
    case 2:
      gf = c, bf = x;
      break;
    case 3:
      gf = x, bf = c;
      break;
    case 4:
      rf = x, bf = c;
      break;
    default:
      rf = c, bf = x;
      break;
  }
  r = toByte(rf + m);
  g = toByte(gf + m);
  b = toByte(bf + m);
}

void writeEnrichedPly(const std::filesystem::path& path, const EnrichedCloud& cloud) {
  std::string out =
      "ply\n"
      "format binary_little_endian 1.0\n"
      "comment semsegmap enriched cloud (LiDAR frame); class: id in the class table\n"
      "element vertex " +
      std::to_string(cloud.size()) +
      "\n"
      "property float x\n"
      "property float y\n"
      "property float z\n"
      "property uchar red\n"
      "property uchar green\n"
      "property uchar blue\n"
      "property ushort class\n"
      "property uchar has_color\n"
      "end_header\n";
  constexpr size_t kVertexBytes = 3 * 4 + 3 + 2 + 1;
  out.reserve(out.size() + cloud.size() * kVertexBytes);
  for (const EnrichedPoint& p : cloud) {
    putFloat(out, p.x);
    putFloat(out, p.y);
    putFloat(out, p.z);
    uint8_t r = 0, g = 0, b = 0;
    if (p.has_color) hsvToRgb(p.h, p.s, p.v, r, g, b);
    out.push_back(static_cast<char>(r));
    out.push_back(static_cast<char>(g));
    out.push_back(static_cast<char>(b));
    putLe(out, p.class_id, 2);
    out.push_back(static_cast<char>(p.has_color ? 1 : 0));
  }
  writeBytesAtomically(path, out);
}

}  // namespace semsegmap
