// The two building blocks of localization: the descriptor index (exact and IVF) and geometric
// verification of centroid correspondences (maximum consistent clique, rigid fit).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>
#include <stdexcept>
#include <vector>

#include "semsegmap/core/pose.h"
#include "semsegmap/core/random.h"
#include "semsegmap/localize/descriptor_index.h"
#include "semsegmap/localize/geometric_verification.h"

namespace semsegmap {
namespace {

Eigen::Vector3d uniformPoint(SeededRng& rng, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  return {rng.uniform(lo.x(), hi.x()), rng.uniform(lo.y(), hi.y()), rng.uniform(lo.z(), hi.z())};
}

Pose randomPose(SeededRng& rng, double extent) {
  Eigen::Quaterniond q(rng.gaussian(1), rng.gaussian(1), rng.gaussian(1), rng.gaussian(1));
  Pose T = Pose::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() =
      uniformPoint(rng, Eigen::Vector3d::Constant(-extent), Eigen::Vector3d::Constant(extent));
  return T;
}

double rotationErrorRad(const Pose& a, const Pose& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

TEST(RigidFit, RecoversAnExactTransform) {
  SeededRng rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose T = randomPose(rng, 100);
    std::vector<Eigen::Vector3d> from, to;
    for (int i = 0; i < 12; ++i) {
      from.push_back(uniformPoint(rng, {-30, -30, -5}, {30, 30, 5}));
      to.push_back(T * from.back());
    }
    const Pose fit = rigidFit(from, to);
    EXPECT_LT((fit.matrix() - T.matrix()).cwiseAbs().maxCoeff(), 1e-9) << trial;
  }
}

TEST(RigidFit, IsTheLeastSquaresOptimumWithNoise) {
  SeededRng rng(2);
  const Pose T = randomPose(rng, 50);
  std::vector<Eigen::Vector3d> from, to;
  for (int i = 0; i < 200; ++i) {
    from.push_back(uniformPoint(rng, {-20, -20, -3}, {20, 20, 3}));
    to.push_back(T * from.back() +
                 Eigen::Vector3d(rng.gaussian(0.05), rng.gaussian(0.05), rng.gaussian(0.05)));
  }
  auto cost = [&](const Pose& P) {
    double s = 0;
    for (size_t i = 0; i < from.size(); ++i) s += (P * from[i] - to[i]).squaredNorm();
    return s;
  };
  const Pose fit = rigidFit(from, to);
  EXPECT_LT(translationError(fit, T), 0.05);
  EXPECT_LT(rotationErrorRad(fit, T), 0.005);
  EXPECT_LE(cost(fit), cost(T));
  // Any small rigid perturbation of the optimum costs more.
  for (int axis = 0; axis < 3; ++axis) {
    Pose rotated = fit, shifted = fit;
    rotated.linear() = Eigen::AngleAxisd(1e-3, Eigen::Vector3d::Unit(axis)) * fit.linear();
    shifted.translation() += 1e-3 * Eigen::Vector3d::Unit(axis);
    EXPECT_GT(cost(rotated), cost(fit));
    EXPECT_GT(cost(shifted), cost(fit));
  }
}

TEST(RigidFit, NeverReturnsAReflection) {
  SeededRng rng(3);
  std::vector<Eigen::Vector3d> from, mirrored;
  for (int i = 0; i < 10; ++i) {
    from.push_back(uniformPoint(rng, {-10, -10, -10}, {10, 10, 10}));
    mirrored.push_back(from.back().cwiseProduct(Eigen::Vector3d(-1, 1, 1)));
  }
  const Pose fit = rigidFit(from, mirrored);
  EXPECT_NEAR(fit.linear().determinant(), 1.0, 1e-9);
  EXPECT_LT((fit.linear() * fit.linear().transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-9);
  EXPECT_THROW(rigidFit(from, {}), std::invalid_argument);
}

struct Scenario {
  std::vector<Correspondence> c;
  std::vector<int> truth;  // indices of the true correspondences, ascending
  Pose T_target_local;
};

// True correspondences in a 60 m area; outliers pair a local segment (a true one, as the other
// k-NN candidates of a segment do, or another) with a random target segment.
Scenario makeScenario(uint64_t seed, int n_true, int n_outliers, double noise_m) {
  SeededRng rng(seed);
  Scenario s;
  s.T_target_local = randomPose(rng, 100);
  const Pose T_local_target = s.T_target_local.inverse();
  const Eigen::Vector3d lo(0, 0, 0), hi(60, 60, 8);
  std::vector<Correspondence> all;
  for (int i = 0; i < n_true; ++i) {
    Correspondence c;
    c.target = uniformPoint(rng, lo, hi);
    const Eigen::Vector3d dir(rng.gaussian(1), rng.gaussian(1), rng.gaussian(1));
    c.local = T_local_target * c.target + rng.uniform(0, noise_m) * dir.normalized();
    c.local_id = i;
    c.target_id = i;
    c.descriptor_distance = static_cast<float>(rng.uniform(0.1, 0.5));
    all.push_back(c);
  }
  for (int j = 0; j < n_outliers; ++j) {
    Correspondence c;
    if (n_true > 0 && rng.chance(0.6)) {
      c.local_id = rng.integer(0, n_true - 1);
      c.local = all[static_cast<size_t>(c.local_id)].local;
    } else {
      c.local_id = 1000 + j;
      c.local = T_local_target * uniformPoint(rng, lo, hi);
    }
    c.target = uniformPoint(rng, lo, hi);
    c.target_id = n_true > 0 && rng.chance(0.2) ? rng.integer(0, n_true - 1) : 5000 + j;
    c.descriptor_distance = static_cast<float>(rng.uniform(0.1, 0.5));
    all.push_back(c);
  }
  std::vector<int> perm(all.size());
  std::iota(perm.begin(), perm.end(), 0);
  for (size_t i = perm.size(); i > 1; --i)
    std::swap(perm[i - 1], perm[static_cast<size_t>(rng.integer(0, static_cast<int>(i) - 1))]);
  for (size_t i = 0; i < perm.size(); ++i) {
    s.c.push_back(all[static_cast<size_t>(perm[i])]);
    if (perm[i] < n_true) s.truth.push_back(static_cast<int>(i));
  }
  return s;
}

std::vector<Eigen::Vector3d> pick(const std::vector<Correspondence>& c, const std::vector<int>& idx,
                                  bool local) {
  std::vector<Eigen::Vector3d> out;
  for (int i : idx) out.push_back(local ? c[i].local : c[i].target);
  return out;
}

TEST(Verify, FindsExactlyTheTrueSetAmongSeventyPercentOutliers) {
  for (uint64_t seed = 10; seed < 15; ++seed) {
    const Scenario s = makeScenario(seed, 30, 70, 0.05);
    const VerificationResult r = verify(s.c, {});
    ASSERT_TRUE(r.found) << seed;
    EXPECT_TRUE(r.search_complete);
    EXPECT_EQ(r.inliers, s.truth) << seed;
    // Refined on the true set: the least-squares pose of exactly those correspondences.
    const Pose ls = rigidFit(pick(s.c, s.truth, true), pick(s.c, s.truth, false));
    EXPECT_LT((r.T_target_local.matrix() - ls.matrix()).cwiseAbs().maxCoeff(), 1e-9);
    // The rotation error acts over a lever arm of up to ~170 m (the frames' offset).
    EXPECT_LT(translationError(r.T_target_local, s.T_target_local), 0.1) << seed;
    EXPECT_LT(rotationErrorRad(r.T_target_local, s.T_target_local), 1e-3) << seed;
  }
}

TEST(Verify, NoiseFreeCorrespondencesGiveTheExactPose) {
  const Scenario s = makeScenario(20, 30, 70, 0.0);
  const VerificationResult r = verify(s.c, {});
  ASSERT_TRUE(r.found);
  EXPECT_EQ(r.inliers, s.truth);
  EXPECT_LT(translationError(r.T_target_local, s.T_target_local), 1e-6);
  EXPECT_LT(rotationErrorRad(r.T_target_local, s.T_target_local), 1e-6);
}

TEST(Verify, KnnLikeOutlierRatesOfNinetyFivePercent) {
  // 30 true local segments with 15 wrong candidates each, 20 more local segments whose 16
  // candidates are all wrong: 800 correspondences, 96 % outliers.
  const Scenario s = makeScenario(30, 30, 770, 0.05);
  const VerificationResult r = verify(s.c, {});
  ASSERT_TRUE(r.found);
  EXPECT_TRUE(r.search_complete);
  EXPECT_EQ(r.inliers, s.truth);
  EXPECT_LT(translationError(r.T_target_local, s.T_target_local), 0.1);
}

TEST(Verify, TooFewTrueCorrespondencesAreNotFound) {
  const Scenario s = makeScenario(40, 5, 60, 0.05);
  GeometricVerificationConfig cfg;
  cfg.min_inliers = 6;
  EXPECT_FALSE(verify(s.c, cfg).found);
  cfg.min_inliers = 5;  // the same five are enough when five are asked for
  const VerificationResult r = verify(s.c, cfg);
  ASSERT_TRUE(r.found);
  EXPECT_EQ(r.inliers, s.truth);
  EXPECT_FALSE(verify({}, cfg).found);
}

TEST(Verify, ASegmentIsUsedOnceInAClique) {
  Scenario s = makeScenario(50, 8, 0, 0.0);
  for (Correspondence& c : s.c) c.descriptor_distance = 0.1f;
  const std::vector<Correspondence> truth = s.c;
  // Geometrically consistent with everything, but a second target for a local segment and a
  // second local segment for a target: without the id rule the clique would be 10.
  Correspondence a = truth[0], b = truth[1];
  a.target += Eigen::Vector3d(0.05, 0, 0);
  a.target_id = 100;
  a.descriptor_distance = 0.5f;
  b.local += Eigen::Vector3d(0.05, 0, 0);
  b.local_id = 200;
  b.descriptor_distance = 0.5f;
  s.c.push_back(a);
  s.c.push_back(b);
  const VerificationResult r = verify(s.c, {});
  ASSERT_TRUE(r.found);
  EXPECT_EQ(r.clique_size, 8u);
  std::set<int64_t> local_ids, target_ids;
  for (int i : r.inliers) {
    EXPECT_TRUE(local_ids.insert(s.c[i].local_id).second);
    EXPECT_TRUE(target_ids.insert(s.c[i].target_id).second);
  }
  // Four cliques of eight exist; the smaller summed descriptor distance picks the true one.
  EXPECT_EQ(r.inliers, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
}

TEST(Verify, TiesGoToTheSmallerDescriptorDistance) {
  // The same eight local segments match two places 1 km apart equally well geometrically.
  const Scenario s = makeScenario(60, 8, 0, 0.0);
  std::vector<Correspondence> c = s.c;
  for (Correspondence& x : c) x.descriptor_distance = 1.0f;
  for (const Correspondence& x : s.c) {
    Correspondence y = x;
    y.target += Eigen::Vector3d(1000, 0, 0);
    y.target_id += 100;
    y.descriptor_distance = 0.5f;
    c.push_back(y);
  }
  VerificationResult r = verify(c, {});
  ASSERT_TRUE(r.found);
  EXPECT_EQ(r.inliers.front(), 8);
  EXPECT_NEAR(r.T_target_local.translation().x() - s.T_target_local.translation().x(), 1000, 1e-6);
  for (size_t i = 8; i < c.size(); ++i) c[i].descriptor_distance = 2.0f;
  r = verify(c, {});
  ASSERT_TRUE(r.found);
  EXPECT_EQ(r.inliers.back(), 7);
}

TEST(Verify, RejectsMirrorAndCollinearSolutions) {
  SeededRng rng(70);
  std::vector<Correspondence> mirror, line;
  for (int i = 0; i < 10; ++i) {
    Correspondence c;
    c.local = uniformPoint(rng, {-20, -20, -5}, {20, 20, 5});
    c.target = c.local.cwiseProduct(Eigen::Vector3d(-1, 1, 1)) + Eigen::Vector3d(5, 5, 0);
    c.local_id = c.target_id = i;
    mirror.push_back(c);
    c.local = Eigen::Vector3d(3.0 * i, 0, 0);
    c.target = c.local + Eigen::Vector3d(5, 5, 0);
    line.push_back(c);
  }
  const VerificationResult m = verify(mirror, {});
  EXPECT_EQ(m.clique_size, 10u);  // every pairwise distance agrees...
  EXPECT_FALSE(m.found);          // ...but no rotation maps one onto the other
  const VerificationResult l = verify(line, {});
  EXPECT_EQ(l.clique_size, 10u);
  EXPECT_FALSE(l.found);  // the rotation about the line is free
}

TEST(Verify, ANodeBudgetStopsTheSearch) {
  const Scenario s = makeScenario(80, 30, 300, 0.05);
  GeometricVerificationConfig cfg;
  cfg.max_search_nodes = 3;
  const VerificationResult r = verify(s.c, cfg);
  EXPECT_FALSE(r.search_complete);
  EXPECT_LE(r.search_nodes, 4u);
}

DescriptorMatrix unitRows(DescriptorMatrix m) {
  m.rowwise().normalize();
  return m;
}

DescriptorMatrix gaussianRows(SeededRng& rng, int n, int d) {
  DescriptorMatrix m(n, d);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < d; ++j) m(i, j) = static_cast<float>(rng.gaussian(1));
  return m;
}

// Every row is nearest-first brute force (double precision) of the queries.
void expectBruteForce(const DescriptorMatrix& db, const DescriptorMatrix& q, const Neighbours& nn) {
  for (int i = 0; i < q.rows(); ++i) {
    std::vector<std::pair<double, int>> all;
    for (int j = 0; j < db.rows(); ++j)
      all.emplace_back((db.row(j) - q.row(i)).cast<double>().squaredNorm(), j);
    std::sort(all.begin(), all.end());
    for (int j = 0; j < nn.k; ++j) {
      EXPECT_EQ(nn.id(i, j), all[j].second) << i << " " << j;
      EXPECT_NEAR(nn.squaredDistance(i, j), all[j].first, 1e-4 * (1 + all[j].first));
    }
  }
}

TEST(DescriptorIndex, ExactSearchIsBruteForce) {
  SeededRng rng(90);
  const DescriptorMatrix db = gaussianRows(rng, 2000, 32), q = gaussianRows(rng, 40, 32);
  DescriptorIndex index;
  index.build(db);
  EXPECT_FALSE(index.approximate());
  EXPECT_EQ(index.size(), 2000u);
  EXPECT_EQ(index.dimension(), 32);
  const Neighbours nn = index.search(q, 10);
  ASSERT_EQ(nn.queries(), 40u);
  expectBruteForce(db, q, nn);
  // A column-major matrix and a strided block (rows of a wider matrix) give the same answers.
  const Eigen::MatrixXf col_major = q;
  EXPECT_EQ(index.search(col_major, 10).ids, nn.ids);
  DescriptorMatrix wide(40, 40);
  wide.leftCols(32) = q;
  EXPECT_EQ(index.search(wide.leftCols(32), 10).ids, nn.ids);
  EXPECT_EQ(index.search(q).k, 16);  // k <= 0: the configured k
  EXPECT_THROW(index.search(gaussianRows(rng, 3, 31), 10), std::invalid_argument);
}

TEST(DescriptorIndex, EmptyAndSmallIndexesPadWithMinusOne) {
  SeededRng rng(91);
  const DescriptorMatrix q = gaussianRows(rng, 5, 8);
  DescriptorIndex never_built;
  const Neighbours none = never_built.search(q, 4);
  EXPECT_EQ(none.ids, std::vector<int64_t>(20, -1));
  EXPECT_TRUE(std::isinf(none.squaredDistance(4, 3)));
  DescriptorIndex empty;
  empty.build(DescriptorMatrix(0, 8));
  EXPECT_EQ(empty.search(q, 4).ids, std::vector<int64_t>(20, -1));
  DescriptorIndex three;
  three.build(gaussianRows(rng, 3, 8));
  const Neighbours nn = three.search(q, 5);
  for (size_t i = 0; i < nn.queries(); ++i) {
    EXPECT_GE(nn.id(i, 2), 0);
    EXPECT_EQ(nn.id(i, 3), -1);
    EXPECT_TRUE(std::isinf(nn.squaredDistance(i, 4)));
  }
}

// Fraction of the exact k nearest that the approximate search returned.
double recallAtK(const Neighbours& approx, const Neighbours& exact) {
  size_t hits = 0;
  for (size_t i = 0; i < exact.queries(); ++i) {
    const std::set<int64_t> truth(exact.idsOf(i), exact.idsOf(i) + exact.k);
    for (int j = 0; j < approx.k; ++j) hits += truth.count(approx.id(i, j));
  }
  return static_cast<double>(hits) / static_cast<double>(exact.ids.size());
}

Neighbours exactSearch(const DescriptorMatrix& db, const DescriptorMatrix& q, int k) {
  DescriptorIndexConfig cfg;
  cfg.exact_below = static_cast<size_t>(db.rows()) + 1;
  DescriptorIndex exact(cfg);
  exact.build(db);
  EXPECT_FALSE(exact.approximate());
  return exact.search(q, k);
}

TEST(DescriptorIndex, IvfAgreesWithExactSearchOnClusteredDescriptors) {
  // Unit-norm 64-d descriptors around 300 centres, as learned descriptors of similar segments
  // gather; the queries come from the same distribution, not from the map.
  SeededRng rng(92);
  const int d = 64;
  const DescriptorMatrix centres = unitRows(gaussianRows(rng, 300, d));
  auto clustered = [&](int n) {
    DescriptorMatrix m = gaussianRows(rng, n, d) * 0.08f;
    for (int i = 0; i < n; ++i) m.row(i) += centres.row(rng.integer(0, 299));
    return unitRows(m);
  };
  const DescriptorMatrix db = clustered(50000), q = clustered(300);
  DescriptorIndexConfig cfg;
  cfg.exact_below = 10000;
  DescriptorIndex ivf(cfg);
  ivf.build(db);
  EXPECT_TRUE(ivf.approximate());
  EXPECT_EQ(ivf.size(), 50000u);
  const double recall = recallAtK(ivf.search(q, 16), exactSearch(db, q, 16));
  EXPECT_GE(recall, 0.95);
  RecordProperty("recall_at_16", std::to_string(recall));
  EXPECT_THROW(ivf.search(q.leftCols(32), 16), std::invalid_argument);
}

TEST(DescriptorIndex, IvfOnUniformDescriptorsNeedsMoreProbes) {
  // Uniform on the sphere, the worst case for any index: the default probes fall short of 0.95,
  // more reach it on the same lists, and probing every list is exhaustive.
  SeededRng rng(93);
  const DescriptorMatrix db = unitRows(gaussianRows(rng, 50000, 64));
  const DescriptorMatrix q = unitRows(gaussianRows(rng, 200, 64));
  DescriptorIndexConfig cfg;
  cfg.exact_below = 10000;
  DescriptorIndex ivf(cfg);
  ivf.build(db);
  ASSERT_TRUE(ivf.approximate());
  EXPECT_EQ(ivf.lists(), 894u);  // 4 sqrt(n)
  const Neighbours exact = exactSearch(db, q, 16);
  const double few = recallAtK(ivf.search(q, 16), exact);
  ivf.setProbes(static_cast<int>(ivf.lists()) * 3 / 4);
  const double many = recallAtK(ivf.search(q, 16), exact);
  ivf.setProbes(static_cast<int>(ivf.lists()));
  const double all = recallAtK(ivf.search(q, 16), exact);
  EXPECT_GT(many, few);
  EXPECT_GE(many, 0.95);
  EXPECT_GE(all, 0.999);
  RecordProperty("recall_at_16_default_probes", std::to_string(few));
  RecordProperty("recall_at_16_three_quarters_of_the_lists", std::to_string(many));
}

}  // namespace
}  // namespace semsegmap
