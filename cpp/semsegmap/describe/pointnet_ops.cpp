// Farthest point sampling keeps, per point, its squared distance to the chosen set and updates it
// with each new pick: O(n m) and no allocation beyond that one array. Ball query is the plain
// O(n m) scan; segments have a few hundred points per set abstraction level, where a spatial
// index costs more than it saves.
#include "semsegmap/describe/pointnet_ops.h"

#include <limits>
#include <stdexcept>
#include <string>

namespace semsegmap {

namespace {

inline float squaredDistance(const float* a, const float* b) {
  const float dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz;
}

}  // namespace

void farthestPointSample(const float* xyz, int n, int m, int start, int* out,
                         std::vector<float>& scratch) {
  if (n <= 0 || m <= 0 || m > n || start < 0 || start >= n) {
    throw std::invalid_argument(
        "farthestPointSample: need 0 < m <= n and 0 <= start < n, got n=" + std::to_string(n) +
        " m=" + std::to_string(m) + " start=" + std::to_string(start));
  }
  scratch.assign(static_cast<size_t>(n), std::numeric_limits<float>::infinity());
  float* nearest = scratch.data();
  int current = start;
  for (int s = 0; s < m; ++s) {
    out[s] = current;
    nearest[current] = -1.0f;  // chosen: never the farthest again, even among duplicates
    const float* c = xyz + 3 * current;
    int best = -1;
    float best_distance = -1.0f;
    for (int i = 0; i < n; ++i) {
      if (nearest[i] < 0.0f) continue;
      const float d = squaredDistance(xyz + 3 * i, c);
      if (d < nearest[i]) nearest[i] = d;
      if (nearest[i] > best_distance) {
        best_distance = nearest[i];
        best = i;
      }
    }
    current = best;
  }
}

std::vector<int> farthestPointSample(const float* xyz, int n, int m, int start) {
  std::vector<int> out(static_cast<size_t>(m > 0 ? m : 0));
  std::vector<float> scratch;
  farthestPointSample(xyz, n, m, start, out.data(), scratch);
  return out;
}

void ballQuery(const float* xyz, int n, const float* centres, int m, float radius, int k,
               int* out) {
  if (n <= 0 || m < 0 || k <= 0) {
    throw std::invalid_argument(
        "ballQuery: need n > 0, m >= 0 and k > 0, got n=" + std::to_string(n) +
        " m=" + std::to_string(m) + " k=" + std::to_string(k));
  }
  const float r2 = radius * radius;
  for (int c = 0; c < m; ++c) {
    const float* centre = centres + 3 * c;
    int* row = out + static_cast<size_t>(c) * k;
    int found = 0;
    for (int i = 0; i < n && found < k; ++i) {
      if (squaredDistance(xyz + 3 * i, centre) < r2) row[found++] = i;
    }
    if (found == 0) {
      // Only for centres that are not among the points; the nearest point keeps the group
      // meaningful instead of gathering garbage.
      float best = std::numeric_limits<float>::infinity();
      for (int i = 0; i < n; ++i) {
        const float d = squaredDistance(xyz + 3 * i, centre);
        if (d < best) {
          best = d;
          row[0] = i;
        }
      }
      found = 1;
    }
    for (int j = found; j < k; ++j) row[j] = row[0];
  }
}

std::vector<int> ballQuery(const float* xyz, int n, const float* centres, int m, float radius,
                           int k) {
  std::vector<int> out(static_cast<size_t>(m > 0 ? m : 0) * static_cast<size_t>(k > 0 ? k : 0));
  ballQuery(xyz, n, centres, m, radius, k, out.data());
  return out;
}

}  // namespace semsegmap
