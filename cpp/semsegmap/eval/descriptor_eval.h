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
  // Per query: the run-time estimate of its completeness (estimatedCompleteness); empty: none.
  std::vector<double> estimated;
};
// Segments with at least `min_observations` observations contribute.
RetrievalQueries makeRetrievalQueries(const TrainingSet& set, size_t min_observations = 2);

// The one-scan wake-ups' retrieval: every observation of the sources from `first_wake_up_source`
// on (a pipeline started empty on one scan each) looks for the target of its landmark
// (landmarkLabels: same object, same class) with the nearest centroid, among `targets` (the map
// run's final observations). An observation whose landmark no target holds is no query.
RetrievalQueries makeWakeUpQueries(const TrainingSet& set, const std::vector<size_t>& targets,
                                   uint16_t first_wake_up_source);

// The run-time completeness estimate (segment/completeness.h) of every observation of the set,
// from the kept observations of its segment in the order they were taken.
std::vector<double> estimatedCompleteness(const TrainingSet& set, size_t window_frames);

// How well the estimate agrees with the simulator's completeness over the queries.
struct CompletenessAgreement {
  size_t window_frames = 0;
  double spearman = 0.0;   // rank correlation of estimate and truth
  double same_band = 0.0;  // share of the queries whose estimate is in their true band
  std::vector<std::vector<size_t>> confusion;  // [true band][estimated band]: queries
};
CompletenessAgreement completenessAgreement(const RetrievalQueries& q,
                                            const std::vector<CompletenessBand>& bands,
                                            size_t window_frames);

struct DescriptorRetrieval {
  std::string descriptor;
  std::vector<int> ranks;                        // per query
  std::vector<std::vector<double>> band_curves;  // per band: fraction within k = 1..max_k
  std::vector<size_t> band_counts;
  // The same per band of the estimated completeness (RetrievalQueries::estimated); empty: none.
  std::vector<std::vector<double>> estimated_band_curves;
  std::vector<size_t> estimated_band_counts;
  std::vector<double> all_curve;  // over all queries, k = 1..max(max_k, 16)
  double top1 = 0, top16 = 0;     // over all queries
  double segments_per_second = 0;
};

DescriptorRetrieval evaluateRetrieval(Describer& describer, const TrainingSet& set,
                                      const RetrievalQueries& q,
                                      const std::vector<CompletenessBand>& bands, int max_k);

}  // namespace semsegmap
