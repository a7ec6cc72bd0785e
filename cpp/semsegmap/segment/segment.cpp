#include "semsegmap/segment/segment.h"

#include <algorithm>

namespace semsegmap {

double Segment::completeness(size_t k) const {
  size_t most = 0;
  for (const auto& o : observations) most = std::max(most, o.n_points);
  return most ? static_cast<double>(observations.at(k).n_points) / most : 0.0;
}

}  // namespace semsegmap
