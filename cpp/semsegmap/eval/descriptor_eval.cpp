#include "semsegmap/eval/descriptor_eval.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include "semsegmap/eval/retrieval.h"
#include "semsegmap/segment/completeness.h"

namespace semsegmap {

std::vector<CompletenessBand> defaultCompletenessBands() {
  return {{0.0, 0.3, "<30%"},
          {0.3, 0.6, "30-60%"},
          {0.6, 0.9, "60-90%"},
          {0.9, std::numeric_limits<double>::infinity(), ">=90%"}};
}

namespace {

// The observations of each segment (of each source), in the order they were taken.
std::map<std::pair<uint16_t, int64_t>, std::vector<size_t>> observationsBySegment(
    const TrainingSet& set) {
  std::map<std::pair<uint16_t, int64_t>, std::vector<size_t>> by_segment;
  for (size_t i = 0; i < set.observations.size(); ++i)
    by_segment[{set.observations[i].source, set.observations[i].segment}].push_back(i);
  return by_segment;
}

}  // namespace

RetrievalQueries makeRetrievalQueries(const TrainingSet& set, size_t min_observations) {
  RetrievalQueries q;
  for (const auto& [key, obs] : observationsBySegment(set)) {
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

RetrievalQueries makeWakeUpQueries(const TrainingSet& set, const std::vector<size_t>& targets,
                                   uint16_t first_wake_up_source) {
  const std::vector<int> labels = landmarkLabels(set);
  std::multimap<int, int> targets_of;  // landmark label -> index into `targets`
  for (size_t t = 0; t < targets.size(); ++t)
    targets_of.emplace(labels[targets[t]], static_cast<int>(t));
  RetrievalQueries q;
  q.targets = targets;
  for (size_t i = 0; i < set.observations.size(); ++i) {
    const TrainingObservation& o = set.observations[i];
    if (o.source < first_wake_up_source) continue;
    // One object can be several targets (a long facade cut in two): the nearest is the truth.
    int best = -1;
    float best_d = std::numeric_limits<float>::infinity();
    for (auto [it, end] = targets_of.equal_range(labels[i]); it != end; ++it) {
      const float d = (set.observations[targets[it->second]].centroid - o.centroid).norm();
      if (d < best_d) best_d = d, best = it->second;
    }
    if (best < 0) continue;
    q.queries.push_back(i);
    q.truth.push_back(best);
    q.completeness.push_back(static_cast<double>(o.n_points) /
                             set.observations[targets[static_cast<size_t>(best)]].n_points);
  }
  return q;
}

std::vector<double> estimatedCompleteness(const TrainingSet& set, size_t window_frames) {
  std::vector<double> out(set.observations.size(), 0.0);
  for (const auto& [key, obs] : observationsBySegment(set)) {
    std::vector<ObservationSize> sizes;
    for (size_t i : obs)
      sizes.push_back({set.observations[i].frame_index, set.observations[i].n_points});
    const std::vector<double> e = estimateCompleteness(sizes, window_frames);
    for (size_t k = 0; k < obs.size(); ++k) out[obs[k]] = e[k];
  }
  return out;
}

namespace {

// Ranks from 1, ties sharing their mean rank.
std::vector<double> tiedRanks(const std::vector<double>& v) {
  std::vector<size_t> order(v.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return v[a] < v[b]; });
  std::vector<double> rank(v.size());
  for (size_t i = 0; i < order.size();) {
    size_t j = i;
    while (j < order.size() && v[order[j]] == v[order[i]]) ++j;
    for (size_t k = i; k < j; ++k) rank[order[k]] = 0.5 * static_cast<double>(i + j + 1);
    i = j;
  }
  return rank;
}

double pearson(const std::vector<double>& a, const std::vector<double>& b) {
  const double n = static_cast<double>(a.size());
  if (a.size() < 2) return 0.0;
  const double ma = std::accumulate(a.begin(), a.end(), 0.0) / n;
  const double mb = std::accumulate(b.begin(), b.end(), 0.0) / n;
  double ab = 0, aa = 0, bb = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    ab += (a[i] - ma) * (b[i] - mb);
    aa += (a[i] - ma) * (a[i] - ma);
    bb += (b[i] - mb) * (b[i] - mb);
  }
  return aa > 0 && bb > 0 ? ab / std::sqrt(aa * bb) : 0.0;
}

size_t bandOf(double completeness, const std::vector<CompletenessBand>& bands) {
  for (size_t b = 0; b < bands.size(); ++b)
    if (completeness >= bands[b].lo && completeness < bands[b].hi) return b;
  return bands.size();  // in no band
}

}  // namespace

CompletenessAgreement completenessAgreement(const RetrievalQueries& q,
                                            const std::vector<CompletenessBand>& bands,
                                            size_t window_frames) {
  CompletenessAgreement a;
  a.window_frames = window_frames;
  a.spearman = pearson(tiedRanks(q.completeness), tiedRanks(q.estimated));
  a.confusion.assign(bands.size(), std::vector<size_t>(bands.size(), 0));
  size_t same = 0, counted = 0;
  for (size_t i = 0; i < q.estimated.size(); ++i) {
    const size_t t = bandOf(q.completeness[i], bands), e = bandOf(q.estimated[i], bands);
    if (t == bands.size() || e == bands.size()) continue;
    ++a.confusion[t][e];
    ++counted;
    same += t == e;
  }
  a.same_band = counted ? static_cast<double>(same) / counted : 0.0;
  return a;
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
  const auto byBand = [&](const std::vector<double>& completeness,
                          std::vector<std::vector<double>>& curves, std::vector<size_t>& counts) {
    for (size_t b = 0; b < bands.size(); ++b) {
      std::vector<int> in_band;
      for (size_t i = 0; i < r.ranks.size(); ++i)
        if (bandOf(completeness[i], bands) == b) in_band.push_back(r.ranks[i]);
      counts.push_back(in_band.size());
      curves.push_back(cumulativeRetrieval(in_band, max_k));
    }
  };
  byBand(q.completeness, r.band_curves, r.band_counts);
  if (!q.estimated.empty()) byBand(q.estimated, r.estimated_band_curves, r.estimated_band_counts);
  r.all_curve = cumulativeRetrieval(r.ranks, std::max(max_k, 16));
  r.top1 = r.all_curve[0];
  r.top16 = r.all_curve[15];
  return r;
}

}  // namespace semsegmap
