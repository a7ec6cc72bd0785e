#include "semsegmap/core/time_association.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace semsegmap {

Association associateNearest(const std::vector<double>& queries,
                             const std::vector<double>& candidates, double tolerance_s) {
  if (!(tolerance_s >= 0.0))
    throw std::invalid_argument("time association: the tolerance must be a non-negative number");
  if (!std::is_sorted(candidates.begin(), candidates.end()))
    throw std::invalid_argument("time association: the candidate times are not sorted");
  Association a;
  a.match.resize(queries.size());
  for (size_t q = 0; q < queries.size(); ++q) {
    const double t = queries[q];
    const auto hi = std::lower_bound(candidates.begin(), candidates.end(), t);
    double best = tolerance_s;
    for (auto it : {hi, hi == candidates.begin() ? candidates.end() : hi - 1}) {
      if (it == candidates.end()) continue;
      const double d = std::abs(*it - t);
      if (d <= best) {  // ties go to the earlier candidate, which the second test sees
        best = d;
        a.match[q] = static_cast<size_t>(it - candidates.begin());
      }
    }
    a.unmatched += !a.match[q].has_value();
  }
  return a;
}

}  // namespace semsegmap
