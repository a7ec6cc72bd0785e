// Pairing two streams of timestamps (LiDAR scans and a camera's images, scans and poses): each
// scan takes the nearest stamp of the other stream within a tolerance, or nothing. A scan is
// never paired with a far image: colouring points with a picture taken a second later paints
// the wrong objects.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

namespace semsegmap {

struct Association {
  // For each query time, the index of the nearest candidate within the tolerance.
  std::vector<std::optional<size_t>> match;
  size_t unmatched = 0;  // queries without a candidate within the tolerance
};

// `candidates` must be sorted (non-decreasing); queries may come in any order. Throws
// std::invalid_argument when the candidates are not sorted or the tolerance is negative or NaN.
Association associateNearest(const std::vector<double>& queries,
                             const std::vector<double>& candidates, double tolerance_s);

}  // namespace semsegmap
