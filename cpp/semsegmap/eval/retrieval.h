// Descriptor retrieval (paper section IV-C): how far down the list of nearest target-map
// descriptors the true segment of a query observation comes, as a function of how complete the
// query observation is.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace semsegmap {

// Rank (1 = nearest) of target row `truth[q]` among all rows of `targets` by Euclidean distance
// to query row q; ties count against the truth. One rank per query.
std::vector<int> retrievalRanks(const Eigen::MatrixXf& targets, const Eigen::MatrixXf& queries,
                                const std::vector<int>& truth);

// Fraction of ranks <= k, for k = 1 .. max_k.
std::vector<double> cumulativeRetrieval(const std::vector<int>& ranks, int max_k);

}  // namespace semsegmap
