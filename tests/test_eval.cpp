#include <gtest/gtest.h>

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
