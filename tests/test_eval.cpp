#include <gtest/gtest.h>

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
