// 3dsmoothnet (describe/smoothnet.h, smoothnet_input.h, learn/smoothnet_trainer.h): the local
// reference frame, the SDV grid, the bag of words in the model file, and training on the tiny
// simulated world.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>

#include <Eigen/Geometry>

#include "build_options.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/datasets/dataset_specs.h"
#include "semsegmap/describe/smoothnet_input.h"
#include "temp_dir.h"
#if SEMSEGMAP_WITH_TORCH
#include "semsegmap/describe/smoothnet.h"
#include "semsegmap/learn/smoothnet_trainer.h"
#endif

using namespace semsegmap;
using semsegmap::test_support::TempDir;

namespace {

// A bumpy, lopsided patch with a pole: no symmetry that would leave its frame undetermined.
std::vector<Eigen::Vector3f> bumpyPatch(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.5f, 1.5f);
  std::vector<Eigen::Vector3f> out;
  for (size_t i = 0; i < n; ++i) {
    const float x = u(rng), y = u(rng);
    out.emplace_back(x, y, 0.2f * x * x + 0.1f * y + 0.15f * std::sin(3 * x) * std::cos(2 * y));
  }
  for (int k = 0; k < 40; ++k) out.emplace_back(0.5f, 0.3f, 0.05f * static_cast<float>(k));
  return out;
}

Eigen::Vector3f nearestTo(const std::vector<Eigen::Vector3f>& cloud, const Eigen::Vector3f& at) {
  Eigen::Vector3f best = cloud.front();
  for (const Eigen::Vector3f& p : cloud)
    if ((p - at).norm() < (best - at).norm()) best = p;
  return best;
}

EnrichedCloud enriched(const std::vector<Eigen::Vector3f>& points) {
  EnrichedCloud out(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    out[i].x = points[i].x(), out[i].y = points[i].y(), out[i].z = points[i].z();
    out[i].class_id = cls::kBuilding;
  }
  return out;
}

#if SEMSEGMAP_WITH_TORCH
NetConfig tinySmoothNet() {
  NetConfig c;
  c.kind = DescriptorKind::kSmoothNetBow;
  c.descriptor_dim = 8;
  c.smoothnet_keypoints = 6;
  c.smoothnet_voxels = 8;
  c.smoothnet_width = 4;
  c.smoothnet_local_dim = 8;
  return c;
}
#endif

}  // namespace

// The frame turns with the points, so the grid does not: what makes 3DSmoothNet rotation
// invariant.
TEST(SmoothNetInput, LocalReferenceFrameIsRepeatableUnderRotation) {
  const std::vector<Eigen::Vector3f> patch = bumpyPatch(3000, 1);
  const Eigen::Vector3f keypoint = nearestTo(patch, Eigen::Vector3f(0.1f, 0.0f, 0.0f));
  const float radius = 1.0f;
  Eigen::Matrix3f axes;
  ASSERT_TRUE(localReferenceFrame(pointsWithin(patch, keypoint, radius), keypoint, radius, &axes));
  EXPECT_LT((axes * axes.transpose() - Eigen::Matrix3f::Identity()).norm(), 1e-5f);
  EXPECT_NEAR(axes.determinant(), 1.0f, 1e-5f) << "a right-handed frame";
  const std::vector<float> grid = keypointGrid(patch, keypoint, radius, 16);

  std::mt19937 rng(7);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Matrix3f r =
        Eigen::Quaternionf(Eigen::Vector4f::Random().normalized()).toRotationMatrix();
    const Eigen::Vector3f t(30.0f * trial, -12.0f, 4.0f);
    std::vector<Eigen::Vector3f> moved;
    for (const Eigen::Vector3f& p : patch) moved.push_back(r * p + t);
    std::shuffle(moved.begin(), moved.end(), rng);
    const Eigen::Vector3f k = r * keypoint + t;
    Eigen::Matrix3f turned;
    ASSERT_TRUE(localReferenceFrame(pointsWithin(moved, k, radius), k, radius, &turned));
    EXPECT_LT((turned - axes * r.transpose()).cwiseAbs().maxCoeff(), 1e-3f) << "trial " << trial;
    const std::vector<float> again = keypointGrid(moved, k, radius, 16);
    ASSERT_EQ(again.size(), grid.size());
    float worst = 0.0f;
    for (size_t i = 0; i < grid.size(); ++i) worst = std::max(worst, std::abs(again[i] - grid[i]));
    EXPECT_LT(worst, 1e-4f) << "trial " << trial;
  }
}

TEST(SmoothNetInput, SdvGridSumsToOneWhateverTheDensity) {
  const std::vector<Eigen::Vector3f> patch = bumpyPatch(800, 2);
  const Eigen::Vector3f keypoint = nearestTo(patch, Eigen::Vector3f::Zero());
  const std::vector<float> grid = keypointGrid(patch, keypoint, 1.0f, 16);
  ASSERT_EQ(grid.size(), 16u * 16u * 16u);
  double sum = 0.0;
  size_t occupied = 0;
  for (const float v : grid) {
    EXPECT_GE(v, 0.0f);
    sum += v;
    occupied += v > 0;
  }
  EXPECT_NEAR(sum, 1.0, 1e-5);
  EXPECT_GT(occupied, 100u) << "a surface through the grid";
  EXPECT_LT(occupied, grid.size() / 2) << "but not the whole grid";

  // Each point twice: the same grid (a cell holds the mean of its points' weights).
  std::vector<Eigen::Vector3f> twice = patch;
  twice.insert(twice.end(), patch.begin(), patch.end());
  const std::vector<float> dense = keypointGrid(twice, keypoint, 1.0f, 16);
  for (size_t i = 0; i < grid.size(); ++i) ASSERT_NEAR(dense[i], grid[i], 1e-6f) << i;

  // One point at the centre: the 8 central cells hold equal shares, the most of any.
  const std::vector<float> one = sdvGrid({Eigen::Vector3f(1, 2, 3)}, Eigen::Vector3f(1, 2, 3),
                                         Eigen::Matrix3f::Identity(), 1.0f, 8);
  double one_sum = 0.0;
  for (const float v : one) one_sum += v;
  EXPECT_NEAR(one_sum, 1.0, 1e-5);
  const float centre = one[(3 * 8 + 3) * 8 + 3];
  EXPECT_FLOAT_EQ(one[(4 * 8 + 4) * 8 + 4], centre);
  EXPECT_FLOAT_EQ(one[(3 * 8 + 4) * 8 + 3], centre);
  for (const float v : one) EXPECT_LE(v, centre + 1e-7f);
  EXPECT_EQ(one[0], 0.0f) << "a corner is beyond 1.5 cells of the point";
  // Nothing near: all zero.
  for (const float v : sdvGrid({Eigen::Vector3f(9, 9, 9)}, Eigen::Vector3f::Zero(),
                               Eigen::Matrix3f::Identity(), 1.0f, 8))
    ASSERT_EQ(v, 0.0f);
}

TEST(SmoothNetInput, SupportsOnALineOrTooSmallHaveNoFrame) {
  Eigen::Matrix3f axes = Eigen::Matrix3f::Constant(5.0f);
  std::vector<Eigen::Vector3f> line;
  for (int i = 0; i < 20; ++i) line.emplace_back(0.05f * i, 0.1f * i, 0.0f);
  EXPECT_FALSE(localReferenceFrame(line, line[3], 1.0f, &axes));
  EXPECT_FALSE(localReferenceFrame({line[0], line[1]}, line[0], 1.0f, &axes));
  EXPECT_EQ(axes(0, 0), 5.0f) << "left untouched";
  // A segment of such points is described by all-zero grids, not refused.
  const std::vector<float> grids = smoothNetSample(enriched(line), 4, 1.0f, 8, 1);
  ASSERT_EQ(grids.size(), 4u * 8u * 8u * 8u);
  for (const float v : grids) ASSERT_EQ(v, 0.0f);
  EXPECT_THROW(smoothNetSample(EnrichedCloud{}, 4, 1.0f, 8, 1), std::invalid_argument);
}

#if SEMSEGMAP_WITH_TORCH

// The words are part of the model: saved, loaded, fingerprinted, and a segment gets the same bag.
TEST(SmoothNet, BagOfWordsRoundTripsThroughTheModelFile) {
  TempDir tmp;
  torch::manual_seed(3);
  auto net = std::make_shared<SmoothNetImpl>(tinySmoothNet());
  const std::string before = netFingerprint(*net);
  net->setWords(torch::randn({8, 8}));
  EXPECT_NE(netFingerprint(*net), before) << "the words are fingerprinted";
  const auto path = tmp.path() / "bow.model";
  saveNet(path, *net);
  const auto loaded = loadNet(path, DescriptorKind::kSmoothNetBow);
  EXPECT_EQ(netFingerprint(*loaded), netFingerprint(*net));
  auto& smooth = dynamic_cast<SmoothNetImpl&>(*loaded);
  EXPECT_TRUE(torch::equal(smooth.words(), net->words()));
  EXPECT_EQ(smooth.config().smoothnet_keypoints, 6);
  EXPECT_EQ(smooth.config().smoothnet_voxels, 8);

  const EnrichedCloud a = enriched(bumpyPatch(500, 4)), b = enriched(bumpyPatch(500, 5));
  const auto describe = [](std::shared_ptr<DescriptorNetImpl> with) {
    DescriberOptions options;
    options.net = std::move(with);
    options.threads = 1;
    return makeDescriber(DescriptorKind::kSmoothNetBow, options);
  };
  const auto describer = describe(loaded);
  EXPECT_EQ(describer->dimension(), 8);
  const Eigen::MatrixXf d = describer->describe({{&a}, {&b}});
  const Eigen::MatrixXf again = describe(net)->describe({{&a}, {&b}});
  EXPECT_EQ((d - again).cwiseAbs().maxCoeff(), 0.0f);
  for (Eigen::Index i = 0; i < d.rows(); ++i) {
    EXPECT_NEAR(d.row(i).sum(), 1.0f, 1e-6f) << "shares of the keypoints";
    for (Eigen::Index j = 0; j < d.cols(); ++j)  // whole keypoints: multiples of 1/6
      EXPECT_NEAR(d(i, j) * 6.0f, std::round(d(i, j) * 6.0f), 1e-5f);
  }

  // descriptor.keypoints: another sample size is another describer (its fingerprint says so, so
  // no map built with the model's is queried with it); the model's own changes nothing.
  DescriberOptions ten;
  ten.net = loaded;
  ten.threads = 1;
  ten.smoothnet_keypoints = 10;
  const auto more = makeDescriber(DescriptorKind::kSmoothNetBow, ten);
  EXPECT_EQ(more->fingerprint(), describer->fingerprint() + "/keypoints=10");
  const Eigen::MatrixXf d10 = more->describe({{&a}, {&b}});
  for (Eigen::Index i = 0; i < d10.rows(); ++i) {
    EXPECT_NEAR(d10.row(i).sum(), 1.0f, 1e-6f);
    for (Eigen::Index j = 0; j < d10.cols(); ++j)  // now multiples of 1/10
      EXPECT_NEAR(d10(i, j) * 10.0f, std::round(d10(i, j) * 10.0f), 1e-5f);
  }
  ten.smoothnet_keypoints = 6;
  EXPECT_EQ(makeDescriber(DescriptorKind::kSmoothNetBow, ten)->fingerprint(),
            describer->fingerprint());
  DescriptorConfig from_yaml;  // the pipeline config's descriptor.keypoints reaches the describer
  from_yaml.kind = "3dsmoothnet";
  from_yaml.model = path.string();
  from_yaml.keypoints = 10;
  EXPECT_EQ(makeDescriber(from_yaml, 1)->fingerprint(), more->fingerprint());

  // A 3dsmoothnet header of a version before 4 cannot be: refused, naming the file.
  std::string bytes = readFileBytes(path);
  bytes[6] = 3;
  const auto old = tmp.path() / "old.model";
  writeBytesAtomically(old, bytes);
  try {
    loadNet(old);
    ADD_FAILURE() << "a version 3 3dsmoothnet model was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(old.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("3dsmoothnet came with version 4"), std::string::npos)
        << e.what();
  }
}

// A few epochs on two runs of the tiny world: the loss falls, the words are fitted (k-means, not
// the placeholder axes), and the same seed gives the same model.
TEST(SmoothNet, TrainingOnTwoRunsLearnsKeypointsAndFitsTheWords) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  ExtractionConfig extraction;
  const TrainingSet data = extractTrainingSet(
      {"sim:world=1,run=S0,preset=tiny,frames=40", "sim:world=1,run=S1,preset=tiny,frames=40"},
      PipelineConfig{}, extraction);
  SmoothNetTrainConfig config = defaultSmoothNetTrainConfig();
  config.net.descriptor_dim = 8;
  config.net.smoothnet_keypoints = 8;
  config.net.smoothnet_width = 4;
  config.epochs = 3;
  config.steps_per_epoch = 12;
  config.batch_pairs = 24;
  config.validation_fraction = 0.3;
  config.validation_pairs = 200;
  config.bow_observations = 60;
  config.max_validation_queries = 200;
  config.threads = 1;
  int epochs = 0;
  TrainCallbacks callbacks;
  callbacks.epoch = [&](const EpochStats& s) {
    ++epochs;
    EXPECT_TRUE(std::isfinite(s.loss));
    EXPECT_GT(s.validation.queries, 50u);
  };
  const SmoothNetTrainResult result = trainSmoothNet(data, config, callbacks);
  ASSERT_NE(result.training.net, nullptr);
  EXPECT_EQ(epochs, 3);
  const auto& history = result.training.history;
  EXPECT_LT(history.back().loss, history.front().loss);
  auto& net = dynamic_cast<SmoothNetImpl&>(*result.training.net);
  EXPECT_FALSE(torch::equal(net.words(), torch::eye(8, 8))) << "the words were fitted";
  EXPECT_EQ(result.word_keypoints, 60u * 8u);
  EXPECT_GT(result.segments.queries, 0u);
  EXPECT_GT(result.segments.top5, 0.0);
  // Same seed, same model.
  const SmoothNetTrainResult again = trainSmoothNet(data, config);
  EXPECT_EQ(netFingerprint(*again.training.net), netFingerprint(net));
}

#endif
