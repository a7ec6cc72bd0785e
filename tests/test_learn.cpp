#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numeric>
#include <set>

#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/artefacts/training_cache.h"
#include "semsegmap/datasets/dataset_specs.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/learn/augment.h"
#include "semsegmap/learn/trainer.h"
#include "semsegmap/learn/training_data.h"
#include "semsegmap/sim/world.h"

using namespace semsegmap;

namespace {

EnrichedCloud randomCloud(size_t n, uint32_t seed, ClassId class_id = cls::kBuilding) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  EnrichedCloud cloud(n);
  for (auto& p : cloud) {
    p.x = 10.0f + 4.0f * u(rng), p.y = -5.0f + 2.0f * u(rng), p.z = 3.0f * u(rng);
    p.h = u(rng), p.s = u(rng), p.v = u(rng);
    p.has_color = true;
    p.has_class = true;
    p.class_id = class_id;
  }
  return cloud;
}

float distance(const EnrichedPoint& p, const Eigen::Vector3f& c) {
  return (Eigen::Vector3f(p.x, p.y, p.z) - c).norm();
}

// Observations of `instances` instances, `per_instance` each, spread over two sources.
TrainingSet syntheticSet(int instances, int per_instance) {
  TrainingSet set;
  set.sources = {"a", "b"};
  set.source_worlds = {"w", "w"};  // two runs through one world
  for (int i = 1; i <= instances; ++i)
    for (int k = 0; k < per_instance; ++k) {
      TrainingObservation o;
      o.instance = static_cast<uint16_t>(i);
      o.majority_class = cls::kBuilding;
      o.source = static_cast<uint16_t>(k % 2);
      o.segment = i * 10 + k;
      const EnrichedCloud c = randomCloud(20, static_cast<uint32_t>(i * 100 + k));
      for (const auto& p : c) {
        o.xyzhsv.insert(o.xyzhsv.end(), {p.x, p.y, p.z, p.h, p.s, p.v});
        o.classes.push_back(p.class_id);
        o.modalities.push_back(TrainingObservation::kHasColor | TrainingObservation::kHasClass);
      }
      o.n_points = 20;
      o.frame_index = static_cast<uint32_t>(7 * i + k);
      o.purity = 1.0f;
      set.observations.push_back(std::move(o));
    }
  return set;
}

}  // namespace

// ---- Augmentation ------------------------------------------------------------------------------

TEST(Augment, YawRotationKeepsDistancesToTheCentroid) {
  const EnrichedCloud cloud = randomCloud(500, 1);
  const Eigen::Vector3f c = centroidOf(cloud);
  const EnrichedCloud turned = rotateYaw(cloud, 0.9);
  ASSERT_EQ(turned.size(), cloud.size());
  EXPECT_LT((centroidOf(turned) - c).norm(), 1e-4f);
  double moved = 0.0;
  for (size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_NEAR(distance(turned[i], c), distance(cloud[i], c), 1e-4f);
    EXPECT_FLOAT_EQ(turned[i].z, cloud[i].z);
    moved += std::hypot(turned[i].x - cloud[i].x, turned[i].y - cloud[i].y);
  }
  EXPECT_GT(moved / cloud.size(), 0.3) << "a 0.9 rad turn must move the points";
}

TEST(Augment, ScaleIsAboutTheCentroid) {
  const EnrichedCloud cloud = randomCloud(200, 2);
  const Eigen::Vector3f c = centroidOf(cloud);
  const EnrichedCloud scaled = scaleAboutCentroid(cloud, 1.1);
  EXPECT_LT((centroidOf(scaled) - c).norm(), 1e-4f);
  for (size_t i = 0; i < cloud.size(); ++i)
    EXPECT_NEAR(distance(scaled[i], c), 1.1f * distance(cloud[i], c), 1e-4f);
}

TEST(Augment, JitterMovesPointsBySigma) {
  const EnrichedCloud cloud = randomCloud(5000, 3);
  std::mt19937 rng(3);
  const EnrichedCloud noisy = jitterPoints(cloud, 0.02, rng);
  double sq = 0.0;
  for (size_t i = 0; i < cloud.size(); ++i) sq += std::pow(noisy[i].x - cloud[i].x, 2);
  EXPECT_NEAR(std::sqrt(sq / cloud.size()), 0.02, 0.002);
}

TEST(Augment, DropRemovesAboutTheRequestedFraction) {
  const EnrichedCloud cloud = randomCloud(10000, 4);
  std::mt19937 rng(4);
  EXPECT_NEAR(static_cast<double>(dropPoints(cloud, 0.3, rng).size()), 7000.0, 300.0);
  EXPECT_EQ(dropPoints(cloud, 0.0, rng).size(), cloud.size());
  EXPECT_EQ(dropPoints(cloud, 1.0, rng).size(), 1u) << "one point always survives";
}

TEST(Augment, SectionCutRemovesOneSideOfAPlane) {
  const EnrichedCloud cloud = randomCloud(4000, 5);
  const Eigen::Vector3f c = centroidOf(cloud);
  const Eigen::Vector3f n = Eigen::Vector3f(1, 1, 0).normalized();
  const EnrichedCloud cut = cutByPlane(cloud, n, 0.5);
  size_t beyond = 0;
  for (const auto& p : cloud) beyond += n.dot(Eigen::Vector3f(p.x, p.y, p.z) - c) > 0.5f;
  ASSERT_GT(beyond, 100u);
  EXPECT_EQ(cut.size(), cloud.size() - beyond);
  for (const auto& p : cut) EXPECT_LE(n.dot(Eigen::Vector3f(p.x, p.y, p.z) - c), 0.5f);

  // A random plane placed to cut a given share.
  std::mt19937 rng(5);
  const EnrichedCloud section = cutSection(cloud, 0.25, rng);
  EXPECT_NEAR(static_cast<double>(section.size()), 3000.0, 5.0);
}

TEST(Augment, WrongLabelsChangeAboutTheRequestedFraction) {
  const EnrichedCloud cloud = randomCloud(10000, 6, cls::kVegetation);
  std::mt19937 rng(6);
  const EnrichedCloud relabeled = relabelPoints(cloud, 0.2, 15, rng);
  size_t changed = 0;
  for (const auto& p : relabeled) {
    changed += p.class_id != cls::kVegetation;
    EXPECT_GE(p.class_id, 1);
    EXPECT_LE(p.class_id, 14);
  }
  EXPECT_NEAR(static_cast<double>(changed), 2000.0, 200.0);
}

TEST(Augment, ColourShiftMovesHueCyclically) {
  EnrichedCloud cloud(3);
  cloud[0].h = 0.95f, cloud[0].s = 0.5f, cloud[0].v = 0.9f, cloud[0].has_color = true;
  cloud[1].h = 0.02f, cloud[1].s = 0.5f, cloud[1].v = 0.5f, cloud[1].has_color = true;
  cloud[2].h = 0.3f, cloud[2].s = 0.5f, cloud[2].v = 0.5f, cloud[2].has_color = false;
  const EnrichedCloud up = shiftColor(cloud, 0.1, 1.2, 1.2);
  EXPECT_NEAR(up[0].h, 0.05f, 1e-5f) << "0.95 + 0.1 wraps to 0.05";
  EXPECT_NEAR(up[0].s, 0.6f, 1e-5f);
  EXPECT_FLOAT_EQ(up[0].v, 1.0f) << "value is clamped to 1";
  EXPECT_FLOAT_EQ(up[2].h, 0.3f) << "a point without colour keeps its (meaningless) colour";
  const EnrichedCloud down = shiftColor(cloud, -0.05, 1.0, 1.0);
  EXPECT_NEAR(down[1].h, 0.97f, 1e-5f) << "0.02 - 0.05 wraps to 0.97";
  for (const auto& p : shiftColor(cloud, 3.7, 1.0, 1.0)) {
    EXPECT_GE(p.h, 0.0f);
    EXPECT_LT(p.h, 1.0f);
  }
}

TEST(Augment, AugmentIsPureAndKeepsPoints) {
  const EnrichedCloud cloud = randomCloud(1000, 7);
  const EnrichedCloud copy = cloud;
  std::mt19937 a(7), b(7);
  const EnrichedCloud x = augment(cloud, AugmentConfig{}, a);
  const EnrichedCloud y = augment(cloud, AugmentConfig{}, b);
  EXPECT_GE(x.size(), 500u);  // at most 30 % cut, then at most 20 % dropped
  EXPECT_LT(x.size(), cloud.size() + 1);
  ASSERT_EQ(x.size(), y.size()) << "same seed, same augmentation";
  for (size_t i = 0; i < x.size(); ++i) EXPECT_EQ(x[i].x, y[i].x);
  for (size_t i = 0; i < cloud.size(); ++i) EXPECT_EQ(cloud[i].x, copy[i].x);
}

TEST(Augment, ConfusedSectionTakesTheClassANetworkConfusesItWith) {
  EnrichedCloud cloud = randomCloud(4000, 8, cls::kFence);
  for (size_t i = 0; i < cloud.size(); i += 2) cloud[i].class_id = cls::kPole;
  for (size_t i = 1; i < cloud.size(); i += 4) cloud[i].class_id = cls::kCar;
  std::mt19937 rng(8);
  const EnrichedCloud out = confuseSection(cloud, 0.3, rng);
  ASSERT_EQ(out.size(), cloud.size()) << "relabelled, not removed";
  size_t changed = 0;
  std::set<ClassId> fence_became, pole_became;
  for (size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out[i].x, cloud[i].x);
    if (out[i].class_id == cloud[i].class_id) continue;
    ++changed;
    ASSERT_NE(cloud[i].class_id, cls::kCar) << "a car has no partner class";
    (cloud[i].class_id == cls::kFence ? fence_became : pole_became).insert(out[i].class_id);
  }
  // The cars beyond the plane keep their class: about 3/4 of 30 % of the points change.
  EXPECT_NEAR(static_cast<double>(changed), 0.75 * 1200.0, 120.0);
  ASSERT_EQ(fence_became.size(), 1u) << "one partner for the whole section";
  EXPECT_TRUE(*fence_became.begin() == cls::kBuilding || *fence_became.begin() == cls::kVegetation);
  EXPECT_EQ(pole_became, fence_became) << "a missed pole takes the class behind it";
}

// The same cloud augmented with the default recipe and with `with`, from the same seed.
std::pair<EnrichedCloud, EnrichedCloud> augmentedOffAndOn(const AugmentConfig& with,
                                                          uint32_t seed) {
  const EnrichedCloud cloud = randomCloud(1000, seed);
  std::mt19937 a(seed), b(seed);
  return {augment(cloud, AugmentConfig{}, a), augment(cloud, with, b)};
}

TEST(Augment, ConfusedSectionsOffKeepTheRecipeBeforeThem) {
  AugmentConfig with;
  with.confused_section_probability = 1.0;
  const auto [off, on] = augmentedOffAndOn(with, 9);
  ASSERT_EQ(off.size(), on.size()) << "the section is relabelled after the geometry";
  size_t differ = 0;
  for (size_t i = 0; i < off.size(); ++i) {
    EXPECT_EQ(off[i].x, on[i].x) << "the same draws up to the confused section";
    differ += off[i].class_id != on[i].class_id;
  }
  EXPECT_GT(differ, 0u) << "building points have a partner class (fence)";
}

TEST(Augment, ModalityDropoutTakesAllColourOrAllClassesOfAnObservation) {
  const EnrichedCloud cloud = randomCloud(300, 10);
  AugmentConfig config;
  config.modality_dropout_probability = 0.5;
  int grey = 0, unknown = 0, both = 0;
  const int draws = 400;
  for (int seed = 0; seed < draws; ++seed) {
    std::mt19937 rng(static_cast<uint32_t>(seed));
    const EnrichedCloud out = augment(cloud, config, rng);
    size_t colored = 0, classed = 0;
    for (const EnrichedPoint& p : out) {
      colored += p.has_color;
      classed += p.class_id != cls::kUnknown;
    }
    // All or nothing: a sensor lacks a modality for the whole segment, never for a few points
    // (the 10 % wrong labels never draw unknown).
    ASSERT_TRUE(colored == 0 || colored == out.size()) << seed;
    ASSERT_TRUE(classed == 0 || classed == out.size()) << seed;
    grey += colored == 0, unknown += classed == 0, both += colored == 0 && classed == 0;
  }
  EXPECT_NEAR(grey, draws / 2, draws / 8) << "colour dropped with the probability given";
  EXPECT_NEAR(unknown, draws / 2, draws / 8) << "classes dropped with the probability given";
  EXPECT_NEAR(both, draws / 4, draws / 10) << "the two drawn separately";
  const EnrichedCloud geometry = dropModalities(cloud, true, true);
  EXPECT_EQ(geometry[7].x, cloud[7].x);
  EXPECT_EQ(geometry[7].v, 0.0f) << "grey, as the network input of a point without colour";
}

TEST(Augment, PartialCoverageUnobservesThePointsBeyondAVerticalPlane) {
  const EnrichedCloud cloud = randomCloud(2000, 11);
  std::mt19937 rng(11);
  const EnrichedCloud out = unobserveSection(cloud, 0.4, rng);
  ASSERT_EQ(out.size(), cloud.size()) << "unobserved, not removed";
  std::vector<Eigen::Vector2f> seen, unseen;
  for (size_t i = 0; i < out.size(); ++i) {
    EXPECT_EQ(out[i].x, cloud[i].x);
    ASSERT_EQ(out[i].has_color, out[i].has_class) << "a camera gives both or neither";
    (out[i].has_class ? seen : unseen).emplace_back(out[i].x, out[i].y);
  }
  EXPECT_NEAR(static_cast<double>(unseen.size()), 800.0, 2.0);
  // A vertical plane: some horizontal direction separates the two sets whatever the heights.
  bool separated = false;
  for (int k = 0; k < 3600 && !separated; ++k) {
    const Eigen::Vector2f n(std::cos(k * 0.1f * 3.14159265f / 180.0f),
                            std::sin(k * 0.1f * 3.14159265f / 180.0f));
    float max_seen = -1e9f, min_unseen = 1e9f;
    for (const auto& p : seen) max_seen = std::max(max_seen, n.dot(p));
    for (const auto& p : unseen) min_unseen = std::min(min_unseen, n.dot(p));
    separated = max_seen <= min_unseen + 1e-4f;
  }
  EXPECT_TRUE(separated) << "the unobserved points lie beyond one vertical plane";
  for (const EnrichedPoint& p : out) {
    if (!p.has_class) {
      EXPECT_EQ(p.class_id, cls::kUnknown);
    }
  }
}

TEST(Augment, PartialCoverageOffKeepsTheRecipeBeforeIt) {
  AugmentConfig with;
  with.partial_coverage_probability = 1.0;
  const auto [off, on] = augmentedOffAndOn(with, 12);
  ASSERT_EQ(off.size(), on.size());
  size_t unobserved = 0;
  for (size_t i = 0; i < off.size(); ++i) {
    EXPECT_EQ(off[i].x, on[i].x) << "the same draws up to the partial coverage";
    unobserved += !on[i].has_class;
  }
  EXPECT_GT(unobserved, 0u);
  EXPECT_LT(unobserved, off.size());
}

TEST(Augment, ModalityDropoutOffKeepsTheRecipeBeforeIt) {
  AugmentConfig with;
  with.modality_dropout_probability = 1.0;
  const auto [off, on] = augmentedOffAndOn(with, 11);
  ASSERT_EQ(off.size(), on.size());
  for (size_t i = 0; i < off.size(); ++i) {
    EXPECT_EQ(off[i].x, on[i].x) << "the same draws up to the dropout";
    EXPECT_TRUE(off[i].has_color && !on[i].has_color);
  }
}

// ---- Pairs, split, retrieval -------------------------------------------------------------------

TEST(TrainingData, PositivesShareALandmarkNegativesDoNot) {
  TrainingSet set = syntheticSet(30, 3);
  // Instance 1 is a tree: trunk and crown are one instance but two landmarks.
  set.observations[0].majority_class = cls::kTrunk;
  std::vector<size_t> all(set.observations.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  const PairSampler sampler(set, all);
  EXPECT_EQ(sampler.anchors().size(), set.observations.size() - 1) << "the lone trunk";
  EXPECT_FALSE(sampler.hasPositive(0));
  std::mt19937 rng(1);
  std::set<size_t> positives_seen;
  for (size_t a : sampler.anchors())
    for (int k = 0; k < 20; ++k) {
      const size_t p = sampler.positive(a, rng), n = sampler.negative(a, rng);
      ASSERT_NE(p, a);
      EXPECT_EQ(set.observations[p].instance, set.observations[a].instance);
      EXPECT_EQ(set.observations[p].majority_class, set.observations[a].majority_class);
      EXPECT_NE(set.observations[n].instance, set.observations[a].instance);
      if (a == 4) positives_seen.insert(p);
    }
  EXPECT_EQ(positives_seen, (std::set<size_t>{3, 5})) << "every other observation is drawn";
}

TEST(TrainingData, ValidationSplitIsByInstance) {
  const TrainingSet set = syntheticSet(400, 3);
  const TrainValSplit split = splitByInstance(set, 0.1, 1);
  EXPECT_EQ(split.train.size() + split.validation.size(), set.observations.size());
  std::set<uint16_t> train, val;
  for (size_t i : split.train) train.insert(set.observations[i].instance);
  for (size_t i : split.validation) val.insert(set.observations[i].instance);
  for (uint16_t i : val) EXPECT_EQ(train.count(i), 0u) << "instance " << i << " in both halves";
  EXPECT_NEAR(static_cast<double>(val.size()), 40.0, 15.0);
  // The same object lands in the same half whatever the set.
  const std::vector<uint64_t> keys = objectKeys(set);
  for (size_t i : split.validation) EXPECT_TRUE(isValidationObject(keys[i], 0.1, 1));
  TrainingSet fewer = set;
  fewer.observations.resize(300);
  const TrainValSplit part = splitByInstance(fewer, 0.1, 1);
  for (size_t i : part.validation) EXPECT_TRUE(isValidationObject(keys[i], 0.1, 1));
}

TEST(TrainingData, InstanceIdsAreOnlyComparableWithinAWorld) {
  EXPECT_EQ(worldOf("sim:run=S1,condition=sunrise,frames=9"), "sim:world=1,preset=full");
  EXPECT_EQ(worldOf("sim:world=3,run=S2,preset=tiny"), "sim:world=3,preset=tiny");
  EXPECT_EQ(worldOf("data/run1"), "data/run1");
  TrainingSet set = syntheticSet(3, 2);  // instances 1..3, observed in sources 0 and 1
  set.sources.push_back("c");
  set.source_worlds.push_back("another world");
  TrainingObservation stranger = set.observations[0];  // instance 1, but of another world
  stranger.source = 2;
  set.observations.push_back(stranger);
  std::vector<size_t> all(set.observations.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  const PairSampler sampler(set, all);
  EXPECT_TRUE(sampler.isPositive(0, 1)) << "instance 1 in two runs of world w";
  EXPECT_FALSE(sampler.isPositive(0, 6)) << "instance 1 of another world is another object";
  EXPECT_TRUE(sampler.isNegative(0, 6));
  EXPECT_FALSE(sampler.hasPositive(6));
  EXPECT_NE(objectKeys(set)[0], objectKeys(set)[6]);
}

TEST(TrainingData, RetrievalAccuracyOfHandMadeDescriptors) {
  // One dimension. Database: landmark 0 at 0.0, landmark 1 at 1.0, landmark 2 at 0.12.
  // Queries: 0.05 (0) -> 0.0 hit; 0.1 (0) -> 0.12 miss, but 0.0 is second; 0.9 (1) -> 1.0 hit;
  // 0.5 (landmark 3, not in the database) is no query.
  Eigen::MatrixXf db(3, 1), q(4, 1);
  db << 0.0f, 1.0f, 0.12f;
  q << 0.05f, 0.1f, 0.9f, 0.5f;
  const RetrievalAccuracy acc = retrievalAccuracy(q, {0, 0, 1, 3}, db, {0, 1, 2});
  EXPECT_EQ(acc.queries, 3u);
  EXPECT_DOUBLE_EQ(acc.top1, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(acc.top5, 1.0);
  // Top-5 fails with five distractors nearer than the match.
  Eigen::MatrixXf far(6, 1), one(1, 1);
  far << 0.01f, 0.02f, 0.03f, 0.04f, 0.05f, 1.0f;
  one << 0.0f;
  const RetrievalAccuracy none = retrievalAccuracy(one, {9}, far, {1, 2, 3, 4, 5, 9});
  EXPECT_EQ(none.queries, 1u);
  EXPECT_DOUBLE_EQ(none.top5, 0.0);
  EXPECT_THROW(retrievalAccuracy(q, {0}, db, {0, 1, 2}), std::invalid_argument);
}

TEST(TrainingData, FinalObservationIsTheLastOfEachSegment) {
  TrainingSet set = syntheticSet(2, 3);  // segments 10, 11, 12, 20, 21, 22: one obs each
  set.observations[1].segment = 10;      // segment 10 now has observations 0 and 1
  set.observations[1].source = set.observations[0].source;
  const std::vector<bool> final = finalObservations(set);
  EXPECT_EQ(final, (std::vector<bool>{false, true, true, true, true, true}));
}

TEST(TrainingData, DatasetListSplitsAroundSimSpecs) {
  using V = std::vector<std::string>;
  EXPECT_EQ(splitDatasetSpecs("sim:world=1,run=S1,sim:world=1,run=S1,condition=sunrise"),
            (V{"sim:world=1,run=S1", "sim:world=1,run=S1,condition=sunrise"}));
  EXPECT_EQ(splitDatasetSpecs("data/s1,sim:run=S2,frames=5,/abs/dir,dir2"),
            (V{"data/s1", "sim:run=S2,frames=5", "/abs/dir", "dir2"}));
  EXPECT_EQ(splitDatasetSpecs("sim:run=S1;sim:run=S2"), (V{"sim:run=S1", "sim:run=S2"}));
  EXPECT_EQ(splitDatasetSpecs("sim:"), (V{"sim:"}));
  EXPECT_THROW(splitDatasetSpecs(""), std::invalid_argument);
  EXPECT_THROW(splitDatasetSpecs("sim:run=S1,,dir"), std::invalid_argument);
}

TEST(TrainingData, CacheRoundTripsAndKnowsWhatItWasMadeFrom) {
  const TrainingSet set = syntheticSet(5, 2);
  const auto path = std::filesystem::temp_directory_path() /
                    ("test_learn_cache_" +
                     std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + ".bin");
  writeTrainingCache(path, set, "made from A");
  const auto back = readTrainingCache(path, "made from A");
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(back->sources, set.sources);
  EXPECT_EQ(back->source_worlds, set.source_worlds);
  ASSERT_EQ(back->observations.size(), set.observations.size());
  for (size_t i = 0; i < set.observations.size(); ++i) {
    const auto &x = set.observations[i], &y = back->observations[i];
    EXPECT_EQ(x.instance, y.instance);
    EXPECT_EQ(x.segment, y.segment);
    EXPECT_EQ(x.source, y.source);
    EXPECT_EQ(x.n_points, y.n_points);
    EXPECT_EQ(x.frame_index, y.frame_index);
    EXPECT_EQ(x.xyzhsv, y.xyzhsv);
    EXPECT_EQ(x.classes, y.classes);
    EXPECT_EQ(x.modalities, y.modalities);
  }
  EXPECT_FALSE(readTrainingCache(path, "made from B").has_value());
  EXPECT_FALSE(readTrainingCache(path.string() + ".missing", "made from A").has_value());
  // Truncated and corrupted files are errors, not silently empty data.
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size - 10);
  EXPECT_THROW(readTrainingCache(path, "made from A"), std::runtime_error);
  writeTrainingCache(path, set, "made from A");
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(size / 2));
    f.put('\x5a');
  }
  EXPECT_THROW(readTrainingCache(path, "made from A"), std::runtime_error);
  std::filesystem::remove(path);
}

// A cache whose checksum is right but whose values are not finite (written so by a bug) is
// refused, naming the segment, rather than training on NaN.
TEST(TrainingData, CacheWithANonFiniteValueIsRefused) {
  TrainingSet set = syntheticSet(3, 1);
  set.observations[1].xyzhsv[4] = std::numeric_limits<float>::infinity();
  const auto path = std::filesystem::temp_directory_path() /
                    ("test_learn_cache_nan_" + std::to_string(::getpid()) + ".bin");
  writeTrainingCache(path, set, "made from A");
  try {
    readTrainingCache(path, "made from A");
    ADD_FAILURE() << "a cache holding inf was read";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              path.string() + ": corrupt training cache (a non-finite value in the observation " +
                  "of segment " + std::to_string(set.observations[1].segment) + ")");
  }
  std::filesystem::remove(path);
}

// ---- Extraction from the simulator and training ------------------------------------------------

class SimulatedData : public ::testing::Test {
 protected:
  // One extraction for every test below: the simulator is the slow part.
  static void SetUpTestSuite() {
    ExtractionConfig config;
    config.max_points_per_observation = 1024;
    data_ = new TrainingSet(
        extractTrainingSet({"sim:world=1,run=S2,preset=tiny,frames=20",
                            "sim:world=1,run=S2,preset=tiny,frames=20,condition=sunrise"},
                           PipelineConfig{}, config));
  }
  static void TearDownTestSuite() {
    delete data_;
    data_ = nullptr;
  }
  // Small networks, so that a few steps take a second.
  static TrainConfig tinyTraining() {
    TrainConfig c;
    c.net.num_points = 64;
    c.net.pointnet_width = 8;
    c.net.recon_grid = 8;
    c.net.grid_xy = 16;
    c.net.grid_z = 8;
    c.net.cnn_width = 8;
    c.epochs = 3;
    c.batch_size = 8;
    c.anchors_per_epoch = 64;
    c.warmup_epochs = 1;
    c.validation_fraction = 0.2;
    // One thread: OpenMP's spinning threads crawl when the machine is shared (ctest -j).
    c.threads = 1;
    return c;
  }
  static TrainingSet* data_;
};
TrainingSet* SimulatedData::data_ = nullptr;

TEST_F(SimulatedData, ExtractionGivesObservationsWithPointsAndInstances) {
  const TrainingSet& set = *data_;
  ASSERT_GT(set.observations.size(), 40u);
  EXPECT_EQ(openDataset("sim:world=1,run=S2,preset=tiny,frames=1")->info().first_transient_instance,
            sim::kTrafficInstanceBase);
  ASSERT_EQ(set.source_worlds.size(), 2u);
  EXPECT_EQ(set.source_worlds[0], set.source_worlds[1]) << "one world, two conditions";
  std::map<uint16_t, std::set<uint16_t>> sources_of;
  std::map<uint16_t, int> count;
  for (const auto& o : set.observations) {
    EXPECT_NE(o.instance, 0);
    EXPECT_LT(o.instance, sim::kTrafficInstanceBase) << "parked cars are no landmarks";
    EXPECT_GT(o.purity, 0.8f);
    EXPECT_GE(o.n_points, o.size());
    EXPECT_GT(o.size(), 0u);
    EXPECT_LE(o.size(), 1024u);
    EXPECT_EQ(o.xyzhsv.size(), 6 * o.size());
    // The stored points are the segment's: their centroid is the observation's when none
    // were subsampled away.
    if (o.size() == o.n_points) {
      EXPECT_LT((centroidOf(o.cloud()) - o.centroid).norm(), 1e-2f);
    }
    sources_of[o.instance].insert(o.source);
    ++count[o.instance];
  }
  int observed_often = 0, in_both_runs = 0;
  for (const auto& [instance, n] : count) observed_often += n >= 3;
  for (const auto& [instance, s] : sources_of) in_both_runs += s.size() == 2;
  EXPECT_GE(observed_often, 5) << "segments are observed several times as they grow";
  EXPECT_GE(in_both_runs, 5) << "instance ids are the same in both conditions";
}

TEST_F(SimulatedData, AFewStepsTrainReduceTheLossAndWriteAModel) {
  const auto out = std::filesystem::temp_directory_path() /
                   ("test_learn_model_" +
                    std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + ".pt");
  for (DescriptorKind kind : {DescriptorKind::kSemSegMapNet, DescriptorKind::kSegMapCnn}) {
    TrainConfig config = tinyTraining();
    config.net.kind = kind;
    config.epochs = 6;
    // Plain training: no augmentation and no mining, so that the batch loss is comparable across
    // epochs, and no validation, so that the best epoch is the one of lowest training loss.
    config.augment = false;
    config.warmup_epochs = config.epochs;
    config.validation_fraction = 0.0;
    // Fixed training triplets, to measure the loss on the same thing before and after.
    const TrainValSplit split = splitByInstance(*data_, config.validation_fraction, 1);
    const PairSampler sampler(*data_, split.train);
    std::mt19937 rng(9);
    std::vector<Triplet> fixed;
    for (size_t k = 0; k < 32; ++k) {
      const size_t a = sampler.anchors()[k * 7 % sampler.anchors().size()];
      fixed.push_back({a, sampler.positive(a, rng), sampler.negative(a, rng)});
    }
    torch::manual_seed(config.seed);  // the initial weights trainDescriptor starts from
    const double before = evaluateTriplets(*makeNet(config.net), *data_, fixed, config);

    int epochs_seen = 0;
    TrainCallbacks callbacks;
    callbacks.epoch = [&](const EpochStats&) { ++epochs_seen; };
    callbacks.best = [&](DescriptorNetImpl& net) { saveNet(out, net); };
    const TrainResult result = trainDescriptor(*data_, config, callbacks);
    ASSERT_EQ(result.history.size(), 6u);
    EXPECT_EQ(epochs_seen, 6);
    EXPECT_GT(result.anchors, 0u);
    EXPECT_EQ(result.validation_observations, 0u);
    for (const auto& e : result.history) EXPECT_TRUE(std::isfinite(e.loss));
    const double after = evaluateTriplets(*result.net, *data_, fixed, config);
    EXPECT_LT(after, 0.8 * before) << descriptorName(kind);
    EXPECT_LT(result.history.back().loss, result.history.front().loss) << descriptorName(kind);
    ASSERT_GE(result.best_epoch, 1);
    EXPECT_TRUE(result.history[result.best_epoch - 1].best);

    // The file holds the best epoch, which is also what the result carries.
    const auto loaded = loadNet(out, kind);
    EXPECT_EQ(netFingerprint(*loaded), netFingerprint(*result.net));
    const std::vector<size_t> some = {0, 1, 2};
    const Eigen::MatrixXf x = describeObservations(*loaded, *data_, some, 3);
    const Eigen::MatrixXf y = describeObservations(*result.net, *data_, some, 3);
    EXPECT_LT((x - y).cwiseAbs().maxCoeff(), 1e-5f);
  }
  std::filesystem::remove(out);
}

// With augmentation, hard negatives from epoch 2 and validation: the full recipe, twice.
TEST_F(SimulatedData, TrainingIsDeterministicForASeedAndKeepsTheBestEpoch) {
  const TrainConfig config = tinyTraining();
  const TrainResult a = trainDescriptor(*data_, config);
  const TrainResult b = trainDescriptor(*data_, config);
  ASSERT_EQ(a.history.size(), b.history.size());
  for (size_t i = 0; i < a.history.size(); ++i) {
    EXPECT_EQ(a.history[i].loss, b.history[i].loss);
    EXPECT_EQ(a.history[i].validation.top1, b.history[i].validation.top1);
  }
  EXPECT_EQ(netFingerprint(*a.net), netFingerprint(*b.net));

  EXPECT_GT(a.validation_observations, 0u);
  double best_top1 = -1.0;
  for (const auto& e : a.history) {
    EXPECT_GT(e.validation.queries, 0u);
    EXPECT_GE(e.validation.top5, e.validation.top1);
    best_top1 = std::max(best_top1, e.validation.top1);
  }
  ASSERT_GE(a.best_epoch, 1);
  EXPECT_EQ(a.history[a.best_epoch - 1].validation.top1, best_top1);
  // The returned weights are the best epoch's: they reproduce its validation accuracy.
  const TrainValSplit split = splitByInstance(*data_, config.validation_fraction, 1);
  const RetrievalAccuracy again =
      validationAccuracy(*a.net, *data_, split.validation, config.seed,
                         config.max_validation_queries, config.validation_min_completeness);
  EXPECT_EQ(again.top1, best_top1);
}

// Distillation: the mean squared distance between a LiDAR-only network's descriptors of grey
// observations and the teacher's of the same observations in colour.
double distanceToTeacher(DescriptorNetImpl& student, DescriptorNetImpl& teacher,
                         const TrainingSet& set) {
  std::vector<size_t> all(set.observations.size());
  std::iota(all.begin(), all.end(), size_t{0});
  const Eigen::MatrixXf s = describeObservations(student, set, all, 5);
  const Eigen::MatrixXf t = describeObservations(teacher, set, all, 5);
  return (s - t).rowwise().squaredNorm().mean();
}

TEST_F(SimulatedData, DistillationPullsALidarOnlyStudentTowardsItsColourTeacher) {
  TrainConfig teaching = tinyTraining();
  const std::shared_ptr<DescriptorNetImpl> teacher = trainDescriptor(*data_, teaching).net;
  const std::string teacher_before = netFingerprint(*teacher);

  TrainConfig student = tinyTraining();
  student.net.use_color = student.net.use_classes = false;
  student.epochs = 6;
  student.validation_fraction = 0.0;  // the best epoch is the one of lowest loss
  student.seed = 7;                   // other initial weights than the teacher's
  student.start_from_teacher = false;
  student.distillation_weight = 50.0;
  const TrainResult distilled = trainDescriptor(*data_, student, {}, teacher);
  const TrainResult alone = trainDescriptor(*data_, student);
  EXPECT_EQ(netFingerprint(*teacher), teacher_before) << "the teacher is never trained";
  for (const EpochStats& e : distilled.history) EXPECT_GT(e.distillation_loss, 0.0);
  for (const EpochStats& e : alone.history) EXPECT_EQ(e.distillation_loss, 0.0);
  EXPECT_LT(distilled.history.back().distillation_loss,
            distilled.history.front().distillation_loss);
  const double with = distanceToTeacher(*distilled.net, *teacher, *data_);
  const double without = distanceToTeacher(*alone.net, *teacher, *data_);
  EXPECT_LT(with, 0.25 * without) << "with " << with << ", without " << without;
}

// Starting from the teacher: a LiDAR-only student that has not moved describes a grey
// observation as its teacher describes that observation without colour and classes.
TEST_F(SimulatedData, AStudentStartsFromItsTeachersWeights) {
  TrainConfig teaching = tinyTraining();
  teaching.epochs = 1;
  // Training sets libtorch's thread count, the process's, for itself alone.
  const int callers_threads = torch::get_num_threads();
  teaching.threads = callers_threads == 1 ? 2 : 1;
  const std::shared_ptr<DescriptorNetImpl> teacher = trainDescriptor(*data_, teaching).net;
  EXPECT_EQ(torch::get_num_threads(), callers_threads);
  TrainConfig student = tinyTraining();
  student.net.use_color = student.net.use_classes = false;
  student.epochs = 1;
  student.learning_rate = 1e-30;  // Adam's steps are of the learning rate's size: none
  const TrainResult result = trainDescriptor(*data_, student, {}, teacher);

  // As dropModalities leaves them, so that both networks get the very same input.
  TrainingSet grey = *data_;
  for (TrainingObservation& o : grey.observations)
    for (size_t i = 0; i < o.size(); ++i) {
      std::fill_n(o.xyzhsv.begin() + static_cast<std::ptrdiff_t>(6 * i + 3), 3, 0.0f);
      o.classes[i] = cls::kUnknown;
      o.modalities[i] = 0;
    }
  const std::vector<size_t> some = {0, 5, 10};
  const Eigen::MatrixXf s = describeObservations(*result.net, grey, some, 3);
  const Eigen::MatrixXf t = describeObservations(*teacher, grey, some, 3);
  EXPECT_GT(t.cwiseAbs().maxCoeff(), 1e-3f);
  EXPECT_LT((s - t).cwiseAbs().maxCoeff(), 1e-4f);
}

TEST_F(SimulatedData, ATeacherOfAnotherKindOrSizeIsRefused) {
  TrainConfig config = tinyTraining();
  config.net.kind = DescriptorKind::kSegMapCnn;
  const auto cnn = makeNet(config.net);
  config.net.kind = DescriptorKind::kSemSegMapNet;
  EXPECT_THROW(trainDescriptor(*data_, config, {}, cnn), std::invalid_argument);
  TrainConfig wider = config;
  wider.net.descriptor_dim = 32;
  EXPECT_THROW(trainDescriptor(*data_, config, {}, makeNet(wider.net)), std::invalid_argument);
  wider.net.descriptor_dim = config.net.descriptor_dim;
  wider.net.pointnet_width = 16;  // the same descriptors from other weights: nothing to start from
  EXPECT_THROW(trainDescriptor(*data_, config, {}, makeNet(wider.net)), std::invalid_argument);
  config.distillation_weight = -1;
  EXPECT_THROW(trainDescriptor(*data_, config, {}, makeNet(config.net)), std::invalid_argument);
}

TEST(Trainer, RejectsBadConfigurations) {
  const TrainingSet set = syntheticSet(4, 2);
  TrainConfig config;
  config.net.kind = DescriptorKind::kEigen;
  EXPECT_THROW(trainDescriptor(set, config), std::invalid_argument);
  config.net.kind = DescriptorKind::kSemSegMapNet;
  config.batch_size = 0;
  EXPECT_THROW(trainDescriptor(set, config), std::invalid_argument);
  // Every instance seen once: nothing to learn from.
  config.batch_size = 4;
  EXPECT_THROW(trainDescriptor(syntheticSet(4, 1), config), std::runtime_error);
}
