#include "semsegmap/sim/label_noise.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "semsegmap/core/class_table.h"
#include "semsegmap/core/random.h"

namespace semsegmap::sim {

namespace {

// Value noise: random values on a lattice of `cell` pixels, interpolated smoothly; in [0, 1).
class SmoothField {
 public:
  SmoothField(uint64_t seed, double cell) : seed_(seed), inv_cell_(1.0 / cell) {}
  double at(int x, int y) const {
    const double fx = x * inv_cell_, fy = y * inv_cell_;
    const auto ix = static_cast<int64_t>(std::floor(fx)), iy = static_cast<int64_t>(std::floor(fy));
    const double tx = smooth(fx - ix), ty = smooth(fy - iy);
    const double top = lerp(lattice(ix, iy), lattice(ix + 1, iy), tx);
    const double bottom = lerp(lattice(ix, iy + 1), lattice(ix + 1, iy + 1), tx);
    return lerp(top, bottom, ty);
  }

 private:
  static double smooth(double t) { return t * t * (3.0 - 2.0 * t); }
  static double lerp(double a, double b, double t) { return a + (b - a) * t; }
  double lattice(int64_t x, int64_t y) const {
    return uniformFromHash(hashKeys(seed_, static_cast<uint64_t>(x), static_cast<uint64_t>(y)));
  }
  uint64_t seed_;
  double inv_cell_;
};

// The share of a smooth field below a threshold is not the threshold (interpolated values
// crowd the middle); this maps a wanted area share to the threshold that gives it, measured
// once for the field above (a sum of two such fields would differ).
double thresholdForShare(double share) {
  if (share <= 0) return -1.0;
  // Deciles of the interpolated field (smoothstep between four uniform lattice values),
  // measured by sampling it 4 million times.
  static const double q[11] = {0.0, 0.21, 0.299, 0.372, 0.437, 0.5, 0.562, 0.628, 0.7, 0.79, 1.0};
  const double pos = std::clamp(share, 0.0, 1.0) * 10.0;
  const int i = std::min(9, static_cast<int>(pos));
  return q[i] + (q[i + 1] - q[i]) * (pos - i);
}

// The nearest label left or right of (x, y) that is not a thin object: what a network that
// misses a pole sees through it.
uint8_t background(const Image& labels, int x, int y) {
  for (int d = 1; d < labels.width; ++d) {
    if (x - d >= 0 && !cls::isThin(*labels.at(x - d, y))) return *labels.at(x - d, y);
    if (x + d < labels.width && !cls::isThin(*labels.at(x + d, y))) return *labels.at(x + d, y);
  }
  return cls::kUnknown;
}

}  // namespace

LabelNoise labelNoiseOfLevel(int level) {
  switch (level) {
    case 0:
      return {};
    case 1:
      return {2.0, 0.05, 0.2, 0.0};
    case 2:
      return {4.0, 0.12, 0.4, 0.03};
    case 3:
      return {8.0, 0.25, 0.6, 0.08};
    default:
      throw std::invalid_argument("label noise level " + std::to_string(level) + " is outside 0.." +
                                  std::to_string(kMaxLabelNoiseLevel));
  }
}

Image applyLabelNoise(const Image& labels, const LabelNoise& noise, uint64_t seed) {
  if (labels.channels != 1) throw std::invalid_argument("label noise: not a label image");
  const SmoothField shift_x(hashKeys(seed, 1), 24.0), shift_y(hashKeys(seed, 2), 24.0);
  const SmoothField confused(hashKeys(seed, 3), 48.0), partner(hashKeys(seed, 4), 96.0);
  const SmoothField missed(hashKeys(seed, 5), 32.0), region(hashKeys(seed, 6), 120.0);
  const double confusion_below = thresholdForShare(noise.confusion);
  const double missed_below = thresholdForShare(noise.thin_missed);
  const double region_below = thresholdForShare(noise.wrong_region);
  static const ClassId kRegionClasses[4] = {cls::kBuilding, cls::kVegetation, cls::kTerrain,
                                            cls::kRoad};
  const ClassId region_class = kRegionClasses[hashKeys(seed, 7) % 4];
  Image out(labels.width, labels.height, 1);
  for (int y = 0; y < labels.height; ++y)
    for (int x = 0; x < labels.width; ++x) {
      // Boundaries move: each pixel reads the label a smooth displacement away.
      const int sx = std::clamp(
          x + static_cast<int>(std::lround((2 * shift_x.at(x, y) - 1) * noise.boundary_px)), 0,
          labels.width - 1);
      const int sy = std::clamp(
          y + static_cast<int>(std::lround((2 * shift_y.at(x, y) - 1) * noise.boundary_px)), 0,
          labels.height - 1);
      ClassId c = *labels.at(sx, sy);
      if (cls::isThin(c) && missed.at(x, y) < missed_below) c = background(labels, sx, sy);
      if (confused.at(x, y) < confusion_below) c = cls::confusionPartner(c, partner.at(x, y) < 0.5);
      if (region.at(x, y) < region_below && c != cls::kSky && c != cls::kUnknown) c = region_class;
      *out.at(x, y) = static_cast<uint8_t>(c);
    }
  return out;
}

}  // namespace semsegmap::sim
