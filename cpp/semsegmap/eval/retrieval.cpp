#include "semsegmap/eval/retrieval.h"

#include <stdexcept>

namespace semsegmap {

std::vector<int> retrievalRanks(const Eigen::MatrixXf& targets, const Eigen::MatrixXf& queries,
                                const std::vector<int>& truth) {
  if (targets.cols() != queries.cols())
    throw std::invalid_argument("retrieval: target and query descriptors differ in dimension");
  if (static_cast<size_t>(queries.rows()) != truth.size())
    throw std::invalid_argument("retrieval: one true target per query expected");
  std::vector<int> ranks(truth.size());
  for (Eigen::Index q = 0; q < queries.rows(); ++q) {
    const int t = truth[q];
    if (t < 0 || t >= targets.rows())
      throw std::out_of_range("retrieval: true target out of range");
    const float d_true = (targets.row(t) - queries.row(q)).squaredNorm();
    int closer = 0;
    for (Eigen::Index r = 0; r < targets.rows(); ++r)
      if (r != t && (targets.row(r) - queries.row(q)).squaredNorm() <= d_true) ++closer;
    ranks[q] = closer + 1;
  }
  return ranks;
}

std::vector<double> cumulativeRetrieval(const std::vector<int>& ranks, int max_k) {
  std::vector<double> out(max_k, 0.0);
  if (ranks.empty()) return out;
  for (int k = 1; k <= max_k; ++k) {
    size_t n = 0;
    for (int r : ranks) n += r <= k;
    out[k - 1] = static_cast<double>(n) / ranks.size();
  }
  return out;
}

}  // namespace semsegmap
