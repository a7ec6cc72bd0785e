// The descriptor-retrieval experiment (paper section IV-C): for each earlier (partial)
// observation of a segment, the rank of the segment's final observation among the final
// observations of all segments, by descriptor distance; summarised per completeness band.
#pragma once

#include <string>
#include <vector>

#include "semsegmap/describe/descriptor.h"
#include "semsegmap/learn/training_data.h"

namespace semsegmap {

struct CompletenessBand {
  double lo, hi;  // completeness in [lo, hi)
  std::string name;
};
std::vector<CompletenessBand> defaultCompletenessBands();  // <30 %, 30-60 %, 60-90 %, >=90 %

struct RetrievalQueries {
  std::vector<size_t> targets;       // observation index of each segment's final observation
  std::vector<size_t> queries;       // observation index of each earlier observation
  std::vector<int> truth;            // per query: index into `targets`
  std::vector<double> completeness;  // per query: its points / the final observation's
};
// Segments with at least `min_observations` observations contribute.
RetrievalQueries makeRetrievalQueries(const TrainingSet& set, size_t min_observations = 2);

struct DescriptorRetrieval {
  std::string descriptor;
  std::vector<int> ranks;                        // per query
  std::vector<std::vector<double>> band_curves;  // per band: fraction within k = 1..max_k
  std::vector<size_t> band_counts;
  double top1 = 0, top16 = 0;  // over all queries
  double segments_per_second = 0;
};

DescriptorRetrieval evaluateRetrieval(Describer& describer, const TrainingSet& set,
                                      const RetrievalQueries& q,
                                      const std::vector<CompletenessBand>& bands, int max_k);

}  // namespace semsegmap
