#include "semsegmap/eval/descriptor_eval.h"

#include <chrono>
#include <limits>
#include <map>

#include "semsegmap/eval/retrieval.h"

namespace semsegmap {

std::vector<CompletenessBand> defaultCompletenessBands() {
  return {{0.0, 0.3, "<30%"},
          {0.3, 0.6, "30-60%"},
          {0.6, 0.9, "60-90%"},
          {0.9, std::numeric_limits<double>::infinity(), ">=90%"}};
}

RetrievalQueries makeRetrievalQueries(const TrainingSet& set, size_t min_observations) {
  std::map<std::pair<uint16_t, int64_t>, std::vector<size_t>> by_segment;
  for (size_t i = 0; i < set.observations.size(); ++i)
    by_segment[{set.observations[i].source, set.observations[i].segment}].push_back(i);
  RetrievalQueries q;
  for (const auto& [key, obs] : by_segment) {
    if (obs.size() < min_observations) continue;
    // The final observation is the last one, as in training (learn/finalObservations): it is
    // the one the segment leaves the local map with, so the one a target map stores. A merge or
    // split can leave it smaller than an earlier one, whose completeness is then above 1.
    const size_t final_obs = obs.back();
    const int target = static_cast<int>(q.targets.size());
    q.targets.push_back(final_obs);
    for (size_t i : obs) {
      if (i == final_obs) continue;
      q.queries.push_back(i);
      q.truth.push_back(target);
      q.completeness.push_back(static_cast<double>(set.observations[i].n_points) /
                               set.observations[final_obs].n_points);
    }
  }
  return q;
}

DescriptorRetrieval evaluateRetrieval(Describer& describer, const TrainingSet& set,
                                      const RetrievalQueries& q,
                                      const std::vector<CompletenessBand>& bands, int max_k) {
  auto describeAll = [&](const std::vector<size_t>& indices) {
    Eigen::MatrixXf out(static_cast<Eigen::Index>(indices.size()), describer.dimension());
    const size_t chunk = 256;
    for (size_t start = 0; start < indices.size(); start += chunk) {
      std::vector<EnrichedCloud> clouds;
      for (size_t k = start; k < std::min(indices.size(), start + chunk); ++k)
        clouds.push_back(set.observations[indices[k]].cloud());
      std::vector<DescriptorInput> inputs;
      for (const auto& c : clouds) inputs.push_back({&c});
      const Eigen::MatrixXf d = describer.describe(inputs);
      out.middleRows(static_cast<Eigen::Index>(start), d.rows()) = d;
    }
    return out;
  };
  DescriptorRetrieval r;
  r.descriptor = descriptorName(describer.kind());
  const auto t0 = std::chrono::steady_clock::now();
  const Eigen::MatrixXf targets = describeAll(q.targets);
  const Eigen::MatrixXf queries = describeAll(q.queries);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.segments_per_second = seconds > 0 ? (q.targets.size() + q.queries.size()) / seconds : 0.0;
  r.ranks = retrievalRanks(targets, queries, q.truth);
  for (const auto& band : bands) {
    std::vector<int> in_band;
    for (size_t i = 0; i < r.ranks.size(); ++i)
      if (q.completeness[i] >= band.lo && q.completeness[i] < band.hi)
        in_band.push_back(r.ranks[i]);
    r.band_counts.push_back(in_band.size());
    r.band_curves.push_back(cumulativeRetrieval(in_band, max_k));
  }
  const std::vector<double> all = cumulativeRetrieval(r.ranks, std::max(max_k, 16));
  r.top1 = all[0];
  r.top16 = all[15];
  return r;
}

}  // namespace semsegmap
