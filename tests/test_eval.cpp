#include <gtest/gtest.h>

#include <map>

#include "build_options.h"
#include "semsegmap/datasets/dataset_specs.h"
#include "semsegmap/eval/descriptor_eval.h"
#include "semsegmap/eval/retrieval.h"

using namespace semsegmap;

TEST(Retrieval, RankOfAPlantedMatch) {
  // Ten targets on a line; the query sits next to target 7, so target 7 ranks first, target 6
  // second (it is nearer than 8 by construction), and so on.
  Eigen::MatrixXf targets(10, 2);
  for (int i = 0; i < 10; ++i) targets.row(i) << static_cast<float>(i), 0.0f;
  Eigen::MatrixXf queries(3, 2);
  queries.row(0) << 7.1f, 0.0f;
  queries.row(1) << 6.6f, 0.0f;  // truth 7, but 7 is the nearest: rank 1
  queries.row(2) << 6.6f, 0.0f;  // truth 6: 7 is nearer, rank 2
  const std::vector<int> ranks = retrievalRanks(targets, queries, {7, 7, 6});
  EXPECT_EQ(ranks, (std::vector<int>{1, 1, 2}));
  // A query equidistant to its truth and another target: ties count against the truth.
  Eigen::MatrixXf tie(1, 2);
  tie.row(0) << 2.5f, 0.0f;
  EXPECT_EQ(retrievalRanks(targets, tie, {2})[0], 2);
  EXPECT_THROW(retrievalRanks(targets, queries, {7, 7}), std::invalid_argument);
  EXPECT_THROW(retrievalRanks(targets, queries, {7, 7, 10}), std::out_of_range);
}

TEST(Retrieval, CumulativeCurveOfKnownRanks) {
  const std::vector<double> curve = cumulativeRetrieval({1, 1, 2, 5, 20}, 5);
  ASSERT_EQ(curve.size(), 5u);
  EXPECT_DOUBLE_EQ(curve[0], 0.4);
  EXPECT_DOUBLE_EQ(curve[1], 0.6);
  EXPECT_DOUBLE_EQ(curve[3], 0.6);
  EXPECT_DOUBLE_EQ(curve[4], 0.8);
}

TEST(Retrieval, QueriesRankAgainstTheFinalObservationTrainingUses) {
  // Segment 5 is seen three times and shrinks at the end (a split); segment 6 once (no query).
  TrainingSet set;
  set.sources = {"sim:"};
  const std::vector<std::pair<int64_t, uint32_t>> seen = {{5, 100}, {6, 50}, {5, 400}, {5, 200}};
  for (const auto& [segment, n] : seen) {
    TrainingObservation o;
    o.segment = segment;
    o.n_points = n;
    set.observations.push_back(o);
  }
  const RetrievalQueries q = makeRetrievalQueries(set);
  const std::vector<bool> final = finalObservations(set);
  ASSERT_EQ(q.targets, (std::vector<size_t>{3}));  // the last observation, not the largest
  EXPECT_TRUE(final[q.targets[0]]);
  EXPECT_EQ(q.queries, (std::vector<size_t>{0, 2}));
  EXPECT_EQ(q.truth, (std::vector<int>{0, 0}));
  EXPECT_DOUBLE_EQ(q.completeness[0], 0.5);
  EXPECT_DOUBLE_EQ(q.completeness[1], 2.0);  // larger than the final one: in the top band
  const auto bands = defaultCompletenessBands();
  EXPECT_TRUE(q.completeness[1] >= bands.back().lo && q.completeness[1] < bands.back().hi);
}

TEST(Completeness, AgreementOfAPerfectAndOfAReversedEstimate) {
  RetrievalQueries q;
  q.completeness = {0.1, 0.2, 0.5, 0.7, 0.95, 1.2};
  q.estimated = q.completeness;
  const auto bands = defaultCompletenessBands();
  const CompletenessAgreement same = completenessAgreement(q, bands, 10);
  EXPECT_NEAR(same.spearman, 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(same.same_band, 1.0);
  EXPECT_EQ(same.window_frames, 10u);
  EXPECT_EQ(same.confusion[0][0], 2u);
  EXPECT_EQ(same.confusion[3][3], 2u);
  q.estimated = {0.95, 0.7, 0.7, 0.5, 0.2, 0.1};
  const CompletenessAgreement reversed = completenessAgreement(q, bands, 10);
  EXPECT_LT(reversed.spearman, -0.9);
  EXPECT_EQ(reversed.confusion[0][3], 1u);  // 0.1 estimated 0.95
  EXPECT_EQ(reversed.confusion[0][2], 1u);  // 0.2 estimated 0.7
}

TEST(Completeness, WakeUpQueriesFindTheNearestTargetOfTheirLandmark) {
  // Source 0 is the map run: instance 7 cut into two targets 20 m apart, instance 8 one target.
  // Source 1 is a wake-up: it sees instance 7 near the second target, instance 9 (in no target).
  TrainingSet set;
  set.sources = {"sim:world=1,run=S0", "sim:world=1,run=S2 frame 0"};
  set.source_worlds = {"sim:world=1,preset=full", "sim:world=1,preset=full"};
  const auto add = [&](uint16_t source, int64_t segment, uint16_t instance, float x, uint32_t n) {
    TrainingObservation o;
    o.source = source;
    o.segment = segment;
    o.instance = instance;
    o.majority_class = cls::kBuilding;
    o.centroid = Eigen::Vector3f(x, 0, 0);
    o.n_points = n;
    set.observations.push_back(o);
  };
  add(0, 1, 7, 0.0f, 400);
  add(0, 2, 7, 20.0f, 500);
  add(0, 3, 8, 40.0f, 300);
  add(1, 1, 7, 18.0f, 100);
  add(1, 2, 9, 60.0f, 100);
  const RetrievalQueries q = makeWakeUpQueries(set, {0, 1, 2}, 1);
  ASSERT_EQ(q.queries, (std::vector<size_t>{3}));
  EXPECT_EQ(q.truth, (std::vector<int>{1}));
  EXPECT_DOUBLE_EQ(q.completeness[0], 0.2);
  // A wake-up's segment is seen once: its estimate is the lowest there is.
  EXPECT_DOUBLE_EQ(estimatedCompleteness(set, 10)[3], 0.0);
}

TEST(Completeness, TheEstimateIsMonotoneOverASegmentsObservationsInATinyWorld) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  ExtractionConfig extraction;
  extraction.max_frames = 120;
  extraction.min_purity = 0.0f;
  const TrainingSet set =
      extractTrainingSet({"sim:world=1,run=S0,preset=tiny"}, PipelineConfig{}, extraction);
  const std::vector<double> estimate = estimatedCompleteness(set, 10);
  std::map<int64_t, std::vector<size_t>> by_segment;
  for (size_t i = 0; i < set.observations.size(); ++i)
    by_segment[set.observations[i].segment].push_back(i);
  size_t grown = 0, checked = 0;
  for (const auto& [segment, obs] : by_segment) {
    for (size_t k = 0; k < obs.size(); ++k) {
      const double e = estimate[obs[k]];
      EXPECT_GE(e, 0.0);
      EXPECT_LE(e, 1.0);
      if (k == 0) continue;
      EXPECT_GE(e, estimate[obs[k - 1]]) << "segment " << segment << " observation " << k;
      ++checked;
      grown += e > 0.5;
    }
  }
  EXPECT_GT(checked, 50u);
  EXPECT_GT(grown, 0u);  // segments do stop growing
  // And it says something about the truth: partial observations rank below complete ones.
  const RetrievalQueries q = makeRetrievalQueries(set);
  RetrievalQueries with = q;
  for (size_t i : q.queries) with.estimated.push_back(estimate[i]);
  EXPECT_GT(completenessAgreement(with, defaultCompletenessBands(), 10).spearman, 0.3);
}
