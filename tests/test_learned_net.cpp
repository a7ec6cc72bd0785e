// The learned descriptors: sampling ops against brute force, inputs, triplet loss, gradient
// flow, model files, inference invariances, and that a small network can learn at all.
#include <gtest/gtest.h>

#include <omp.h>
#include <sys/resource.h>
#include <unistd.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <thread>

#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/binary_io.h"
#include "semsegmap/describe/learned_describer.h"
#include "semsegmap/describe/learned_net.h"
#include "semsegmap/describe/net_input.h"
#include "semsegmap/describe/pointnet_ops.h"
#include "semsegmap/describe/semsegmap_net.h"

using namespace semsegmap;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Synthetic segments of a few hundred to a few thousand points, about 2 m in size, with a colour
// and a class each: 0 box surface, 1 wall with a pillar, 2 trunk (cylinder), 3 crown (blob),
// 4 an L-shaped wall whose principal axis and skew are well defined (for the yaw tests).
EnrichedCloud makeShape(int shape, int n, uint64_t seed) {
  std::mt19937 rng(static_cast<uint32_t>(seed));
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::normal_distribution<float> g(0.0f, 1.0f);
  EnrichedCloud cloud(static_cast<size_t>(n));
  for (EnrichedPoint& p : cloud) {
    p.has_color = p.has_class = true;
    switch (shape) {
      case 0: {  // box 2 x 1.2 x 1.5, its six faces
        const int face = static_cast<int>(u(rng) * 6) % 6;
        float c[3] = {u(rng) * 2.0f, u(rng) * 1.2f, u(rng) * 1.5f};
        const float size[3] = {2.0f, 1.2f, 1.5f};
        c[face / 2] = (face % 2) ? size[face / 2] : 0.0f;
        p.x = c[0], p.y = c[1], p.z = c[2];
        p.h = 0.02f, p.s = 0.8f, p.v = 0.6f, p.class_id = cls::kCar;
        break;
      }
      case 1:  // wall 2.5 x 0.1 x 2 with a pillar at one end
        if (u(rng) < 0.8f) {
          p.x = u(rng) * 2.5f, p.y = u(rng) * 0.1f, p.z = u(rng) * 2.0f;
        } else {
          p.x = 2.3f + u(rng) * 0.3f, p.y = u(rng) * 0.4f, p.z = u(rng) * 2.0f;
        }
        p.h = 0.1f, p.s = 0.1f, p.v = 0.8f, p.class_id = cls::kBuilding;
        break;
      case 2: {  // trunk: cylinder radius 0.25, height 2.5
        const float a = u(rng) * 2.0f * static_cast<float>(kPi);
        p.x = 0.25f * std::cos(a), p.y = 0.25f * std::sin(a), p.z = u(rng) * 2.5f;
        p.h = 0.08f, p.s = 0.6f, p.v = 0.3f, p.class_id = cls::kTrunk;
        break;
      }
      case 3:  // crown: gaussian blob
        p.x = 0.7f * g(rng), p.y = 0.6f * g(rng), p.z = 0.5f * g(rng);
        p.h = 0.33f, p.s = 0.7f, p.v = 0.4f + 0.2f * u(rng), p.class_id = cls::kVegetation;
        break;
      default:  // L-shaped wall: 4 m along x, a 1.5 m wing along y at x = 0
        if (u(rng) < 0.75f) {
          p.x = u(rng) * 4.0f, p.y = u(rng) * 0.2f;
        } else {
          p.x = u(rng) * 0.2f, p.y = u(rng) * 1.5f;
        }
        p.z = u(rng) * 2.0f;
        p.h = 0.6f, p.s = 0.5f, p.v = 0.5f, p.class_id = cls::kFence;
        break;
    }
  }
  return cloud;
}

EnrichedCloud transformed(const EnrichedCloud& cloud, double yaw, const Eigen::Vector3d& t) {
  EnrichedCloud out = cloud;
  const double c = std::cos(yaw), s = std::sin(yaw);
  for (EnrichedPoint& p : out) {
    const double x = p.x, y = p.y;
    p.x = static_cast<float>(c * x - s * y + t.x());
    p.y = static_cast<float>(s * x + c * y + t.y());
    p.z = static_cast<float>(p.z + t.z());
  }
  return out;
}

NetConfig tinyConfig(DescriptorKind kind) {
  NetConfig c;
  c.kind = kind;
  c.descriptor_dim = 16;
  c.num_points = 128;
  c.pointnet_width = 8;
  c.cnn_width = 8;
  return c;
}

std::filesystem::path tempDir() {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("semsegmap_test_learned_net_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir;
}

std::string readBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void writeBytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// Expects `f` to throw std::runtime_error whose message names `path` and contains `what`.
template <typename F>
void expectFileError(F f, const std::filesystem::path& path, const std::string& what) {
  try {
    f();
    ADD_FAILURE() << "no exception for " << path;
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
    EXPECT_NE(message.find(what), std::string::npos) << message;
  }
}

torch::Tensor pairwiseDistances(const torch::Tensor& d) {
  return torch::cdist(d.unsqueeze(0), d.unsqueeze(0)).squeeze(0);
}

// A thread's first use of torch set its OpenMP thread count to one, and the enrichment's loops
// in that thread then ran on one core (7 -> 12-14 ms a frame): loading a describer leaves the
// calling thread's count as it was. A fresh thread, because torch does it once per thread.
TEST(ModelFile, LoadingADescriberLeavesTheThreadsOpenMpCountAlone) {
  int before = 0, after = 0;
  std::thread fresh([&] {
    omp_set_num_threads(2);
    before = omp_get_max_threads();
    DescriptorConfig config;
    config.kind = "semsegmap-net";
    config.model =
        (std::filesystem::path(SEMSEGMAP_SOURCE_DIR) / "models" / "semsegmap-net.model").string();
    const auto describer = makeDescriber(config);
    after = omp_get_max_threads();
  });
  fresh.join();
  EXPECT_EQ(before, 2);
  EXPECT_EQ(after, before);
}

}  // namespace

// ---- sampling ops ------------------------------------------------------------------------------

TEST(PointNetOps, FarthestPointSamplingMatchesBruteForce) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int trial = 0; trial < 5; ++trial) {
    const int n = 50 + 37 * trial, m = 5 + 6 * trial;
    std::vector<float> xyz(3 * static_cast<size_t>(n));
    for (float& v : xyz) v = u(rng);
    // A few exact duplicates: ties must still resolve the same way.
    std::copy_n(xyz.begin(), 6, xyz.end() - 6);
    const int start = trial % n;
    const std::vector<int> fast = farthestPointSample(xyz.data(), n, m, start);

    std::vector<int> brute{start};
    while (static_cast<int>(brute.size()) < m) {
      int best = -1;
      float best_d = -1.0f;
      for (int i = 0; i < n; ++i) {
        if (std::find(brute.begin(), brute.end(), i) != brute.end()) continue;
        float nearest = std::numeric_limits<float>::infinity();
        for (const int j : brute) {
          const float dx = xyz[3 * i] - xyz[3 * j], dy = xyz[3 * i + 1] - xyz[3 * j + 1],
                      dz = xyz[3 * i + 2] - xyz[3 * j + 2];
          nearest = std::min(nearest, dx * dx + dy * dy + dz * dz);
        }
        if (nearest > best_d) best_d = nearest, best = i;
      }
      brute.push_back(best);
    }
    EXPECT_EQ(fast, brute) << "trial " << trial;
  }
  EXPECT_THROW(farthestPointSample(std::vector<float>(3).data(), 1, 2, 0), std::invalid_argument);
}

TEST(PointNetOps, BallQueryMatchesBruteForce) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  const int n = 300, m = 40, k = 16;
  const float radius = 0.4f;
  std::vector<float> xyz(3 * n), centres(3 * m);
  for (float& v : xyz) v = u(rng);
  for (float& v : centres) v = 1.5f * u(rng);  // some centres far outside: empty balls
  const std::vector<int> fast = ballQuery(xyz.data(), n, centres.data(), m, radius, k);
  ASSERT_EQ(fast.size(), static_cast<size_t>(m * k));
  int empty_balls = 0;
  for (int c = 0; c < m; ++c) {
    std::vector<int> inside;
    int nearest = 0;
    float nearest_d = std::numeric_limits<float>::infinity();
    for (int i = 0; i < n; ++i) {
      const float dx = xyz[3 * i] - centres[3 * c], dy = xyz[3 * i + 1] - centres[3 * c + 1],
                  dz = xyz[3 * i + 2] - centres[3 * c + 2];
      const float d = dx * dx + dy * dy + dz * dz;
      if (d < radius * radius) inside.push_back(i);
      if (d < nearest_d) nearest_d = d, nearest = i;
    }
    if (inside.empty()) ++empty_balls, inside.push_back(nearest);
    if (inside.size() > static_cast<size_t>(k)) inside.resize(k);
    std::vector<int> expected = inside;
    expected.resize(k, inside.front());
    const std::vector<int> got(fast.begin() + c * k, fast.begin() + (c + 1) * k);
    EXPECT_EQ(got, expected) << "centre " << c;
    EXPECT_EQ(std::set<int>(got.begin(), got.end()), std::set<int>(inside.begin(), inside.end()));
  }
  EXPECT_GT(empty_balls, 0) << "the fixture should exercise the empty-ball fallback";
}

// ---- inputs ------------------------------------------------------------------------------------

TEST(NetInput, SubsampleIsAFunctionOfThePointSet) {
  const EnrichedCloud cloud = makeShape(3, 900, 1);
  EnrichedCloud shuffled = cloud;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(9));
  const auto pick = [](const EnrichedCloud& c, uint64_t salt, int count) {
    std::vector<std::array<float, 3>> out;
    for (const uint32_t i : hashSubsample(c, count, salt)) out.push_back({c[i].x, c[i].y, c[i].z});
    return out;
  };
  EXPECT_EQ(pick(cloud, 7, 256), pick(shuffled, 7, 256));
  EXPECT_NE(pick(cloud, 7, 256), pick(cloud, 8, 256));  // another salt, another subset
  // Fewer points than asked for: every point, then again in the same order.
  const std::vector<uint32_t> all = hashSubsample(cloud, 2000, 7);
  EXPECT_EQ(std::set<uint32_t>(all.begin(), all.begin() + 900).size(), 900u);
  EXPECT_TRUE(std::equal(all.begin(), all.begin() + 900, all.begin() + 900));
}

// A segment half in the picture: the unobserved half is missing from the class histograms, not
// a vote for unknown, so every cell that holds a point with a class is all car, and the cells of
// unobserved points alone are empty.
TEST(NetInput, UnobservedPointsAreMissingFromTheClassHistograms) {
  EnrichedCloud car = makeShape(0, 700, 1);
  for (size_t i = 0; i < car.size(); ++i)
    if (car[i].x > 1.0f) car[i].has_class = false;
  NetConfig config;
  std::mt19937 rng(1);
  const NetInput in = makeNetInput(config, {&car}, rng);
  const torch::Tensor sums = in.class_grid[0].sum(0);
  EXPECT_EQ(in.class_grid[0][cls::kUnknown].sum().item<float>(), 0.0f);
  EXPECT_NEAR(in.class_grid[0][cls::kCar].sum().item<float>(), (sums > 0).sum().item<float>(),
              1e-4);
  // The box's far half (x > 1 of 2 m) fills the grid's last third of cells along x: empty.
  EXPECT_EQ(in.class_grid[0].narrow(1, 2, 1).sum().item<float>(), 0.0f);
  EXPECT_GT(in.class_grid[0].narrow(1, 0, 1).sum().item<float>(), 0.0f);
  // Without any class (a LiDAR alone), every point is in the unknown bin, as a model that does
  // not read classes sees it: the input the shipped models were measured on.
  for (EnrichedPoint& p : car) p.has_class = false;
  NetConfig no_classes = config;
  no_classes.use_classes = false;
  const NetInput grey = makeNetInput(config, {&car}, rng);
  EXPECT_TRUE(torch::equal(grey.class_grid, makeNetInput(no_classes, {&car}, rng).class_grid));
  EXPECT_GT(grey.class_grid[0][cls::kUnknown].sum().item<float>(), 0.0f);
}

TEST(NetInput, ShapesAndRanges) {
  const EnrichedCloud a = makeShape(0, 700, 1), b = makeShape(1, 150, 2);
  NetConfig config;
  std::mt19937 rng(1);
  const NetInput in = makeNetInput(config, {&a, &b}, rng);
  EXPECT_EQ(in.points.sizes(), (std::vector<int64_t>{2, config.num_points, 6}));
  EXPECT_EQ(in.class_grid.sizes(), (std::vector<int64_t>{2, config.num_classes, 3, 3, 3}));
  EXPECT_EQ(in.scale.sizes(), (std::vector<int64_t>{2, 1}));
  EXPECT_EQ(in.target_occupancy.sizes(), (std::vector<int64_t>{2, 1, 16, 16, 16}));
  EXPECT_EQ(in.n_points[0].item<float>(), 700.0f);
  EXPECT_EQ(in.n_points[1].item<float>(), 150.0f);
  const torch::Tensor radius = in.points.narrow(2, 0, 3).norm(2, 2);
  EXPECT_LE(radius.max().item<float>(), 1.0f + 1e-5f);
  EXPECT_GE(radius.max().item<float>(), 0.9f);  // the farthest point is usually kept
  // Each cell's histogram sums to 1 (occupied) or 0 (empty), and the car points are class 11.
  const torch::Tensor sums = in.class_grid.sum(1);
  EXPECT_TRUE(torch::logical_or(torch::isclose(sums, torch::ones_like(sums)), sums == 0)
                  .all()
                  .item<bool>());
  EXPECT_NEAR(in.class_grid[0][cls::kCar].sum().item<float>(), (sums[0] > 0).sum().item<float>(),
              1e-4);
  EXPECT_GT(in.target_occupancy[0].sum().item<float>(), 20.0f);

  config.kind = DescriptorKind::kSegMapCnn;
  const NetInput grid = makeNetInput(config, {&a, &b}, rng);
  EXPECT_EQ(grid.occupancy.sizes(), (std::vector<int64_t>{2, 1, 32, 32, 16}));
  EXPECT_EQ(grid.scale.sizes(), (std::vector<int64_t>{2, 3}));
  // Small segments keep SegMap's minimum extent of 3.2 x 3.2 x 1.6 m.
  EXPECT_FLOAT_EQ(grid.scale[0][0].item<float>(), 3.2f);
  EXPECT_FLOAT_EQ(grid.scale[0][2].item<float>(), 1.6f);

  const EnrichedCloud empty;
  EXPECT_THROW(makeNetInput(config, {&a, &empty}, rng), std::invalid_argument);
  config.recon_grid = 12;
  EXPECT_THROW(makeNetInput(config, {&a}, rng), std::invalid_argument);
}

// ---- loss and gradients ------------------------------------------------------------------------

TEST(TripletLoss, MatchesTheFormula) {
  // Distances by construction: D(A,P) = 3, 1, 2 and D(A,N) = 5, 0.2, 2.5 (3-4-5 triangles).
  const torch::Tensor anchor = torch::zeros({3, 2});
  const torch::Tensor positive = torch::tensor({{3.0f, 0.0f}, {0.0f, 1.0f}, {1.2f, 1.6f}});
  const torch::Tensor negative = torch::tensor({{3.0f, 4.0f}, {0.2f, 0.0f}, {1.5f, 2.0f}});
  const torch::Tensor sigma = torch::tensor({0.5f, 1.0f, 1.2f});
  // max(0.4 + 1.5 - 5, 0) = 0 (hinge); 0.4 + 1 - 0.2 = 1.2; 0.4 + 2.4 - 2.5 = 0.3
  EXPECT_NEAR(tripletLoss(anchor, positive, negative, sigma).item<float>(), (0 + 1.2 + 0.3) / 3,
              1e-5);
  EXPECT_NEAR(tripletLoss(anchor, positive, negative, sigma, 4.0).item<float>(),
              (0.5 + 4.8 + 3.9) / 3, 1e-5);
  // Coinciding anchor and positive: finite gradient.
  const torch::Tensor a = torch::ones({1, 4}, torch::requires_grad());
  tripletLoss(a, torch::ones({1, 4}), torch::zeros({1, 4}), torch::ones({1})).backward();
  EXPECT_TRUE(torch::isfinite(a.grad()).all().item<bool>());
  EXPECT_THROW(tripletLoss(anchor, positive, negative, torch::ones({2})), std::invalid_argument);
}

TEST(LearnedNet, OneDnnConvolutionMatchesTorch) {
  torch::manual_seed(6);
  // A 1x1 kernel on a channels-last batch of 3 (torch's own path there is its reference one),
  // and a strided 3^3 kernel on a single grid.
  torch::nn::Conv2d pointwise(torch::nn::Conv2dOptions(5, 7, 1));
  torch::nn::Conv3d strided(torch::nn::Conv3dOptions(2, 4, 3).stride(2).padding(1));
  const torch::Tensor x2 = torch::randn({3, 6, 4, 5}).permute({0, 3, 1, 2}).requires_grad_();
  const torch::Tensor x3 = torch::randn({1, 2, 8, 8, 4}, torch::requires_grad());
  const auto check = [](auto& conv, const torch::Tensor& x) {
    const torch::Tensor ours = convOnOneDnn(*conv, x);
    const torch::Tensor theirs = conv->forward(x);
    EXPECT_TRUE(torch::allclose(ours, theirs, 1e-4, 1e-5));
    const auto g_ours = torch::autograd::grad({ours.square().sum()}, {x, conv->weight, conv->bias});
    const auto g_theirs =
        torch::autograd::grad({theirs.square().sum()}, {x, conv->weight, conv->bias});
    for (size_t i = 0; i < g_ours.size(); ++i) {
      EXPECT_TRUE(torch::allclose(g_ours[i], g_theirs[i], 1e-3, 1e-4)) << "gradient " << i;
    }
  };
  check(pointwise, x2);
  check(strided, x3);
}

TEST(LearnedNet, GradientsReachEveryParameter) {
  const EnrichedCloud s0 = makeShape(0, 600, 1), s1 = makeShape(0, 400, 2),
                      s2 = makeShape(3, 800, 3);
  for (const DescriptorKind kind : {DescriptorKind::kSemSegMapNet, DescriptorKind::kSegMapCnn}) {
    SCOPED_TRACE(descriptorName(kind));
    torch::manual_seed(1);
    NetConfig config;
    config.kind = kind;
    const auto net = makeNet(config);
    std::mt19937 rng(1);
    const NetInput in = makeNetInput(config, {&s0, &s1, &s2, &s1, &s0, &s2}, rng);
    const NetOutput out = net->forward(in);
    ASSERT_EQ(out.descriptor.sizes(), (std::vector<int64_t>{6, config.descriptor_dim}));
    ASSERT_EQ(out.reconstruction.sizes(), in.target_occupancy.sizes());
    const torch::Tensor d = out.descriptor;
    // A large margin keeps every hinge active, so the triplet term reaches the encoder too.
    const torch::Tensor loss =
        tripletLoss(d.narrow(0, 0, 2), d.narrow(0, 2, 2), d.narrow(0, 4, 2),
                    in.n_points.narrow(0, 2, 2) / in.n_points.narrow(0, 0, 2), 100.0) +
        torch::binary_cross_entropy_with_logits(out.reconstruction, in.target_occupancy);
    loss.backward();
    for (const auto& p : net->named_parameters()) {
      ASSERT_TRUE(p.value().grad().defined()) << p.key();
      EXPECT_TRUE(torch::isfinite(p.value().grad()).all().item<bool>()) << p.key();
      EXPECT_GT(p.value().grad().abs().sum().item<double>(), 0.0) << p.key();
    }
  }
}

// ---- model files -------------------------------------------------------------------------------

TEST(ModelFile, RoundTripAndErrors) {
  const auto dir = tempDir();
  const EnrichedCloud s0 = makeShape(1, 500, 1), s1 = makeShape(2, 1200, 2);
  for (const DescriptorKind kind : {DescriptorKind::kSemSegMapNet, DescriptorKind::kSegMapCnn}) {
    SCOPED_TRACE(descriptorName(kind));
    torch::manual_seed(2);
    NetConfig config = tinyConfig(kind);
    config.descriptor_dim = 24;
    const auto net = makeNet(config);
    net->eval();
    const auto path = dir / (descriptorName(kind) + ".ssmnet");
    saveNet(path, *net);
    EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp." + std::to_string(::getpid())));

    const auto loaded = loadNet(path, kind);
    loaded->eval();
    EXPECT_EQ(loaded->config().descriptor_dim, 24);
    EXPECT_EQ(netFingerprint(*loaded), netFingerprint(*net));
    const NetInput in = makeNetInput(config, {&s0, &s1}, std::vector<uint64_t>{1, 2});
    torch::NoGradGuard no_grad;
    EXPECT_TRUE(torch::equal(loaded->encode(in), net->encode(in)));

    // Another initialisation is another fingerprint.
    EXPECT_NE(netFingerprint(*makeNet(config)), netFingerprint(*net));

    const std::string bytes = readBytes(path);
    const auto truncated = dir / "truncated.ssmnet";
    writeBytes(truncated, bytes.substr(0, bytes.size() - 100));
    expectFileError([&] { loadNet(truncated); }, truncated, "truncated");
    writeBytes(truncated, bytes.substr(0, 20));
    expectFileError([&] { loadNet(truncated); }, truncated, "truncated");

    std::string other_version = bytes;
    other_version[6] = 5;  // the format version follows the 6-byte magic
    const auto future = dir / "future.ssmnet";
    writeBytes(future, other_version);
    expectFileError([&] { loadNet(future); }, future, "version 5");

    const auto bad_magic = dir / "bad_magic.ssmnet";
    writeBytes(bad_magic, "X" + bytes.substr(1));
    expectFileError([&] { loadNet(bad_magic); }, bad_magic, "magic");

    // descriptor_dim is the first config field after magic, version and kind name.
    std::string other_dim = bytes;
    const size_t dim_offset = 6 + 4 + 4 + descriptorName(kind).size();
    ASSERT_EQ(other_dim[dim_offset], 24);
    other_dim[dim_offset] = 32;
    const auto mismatched = dir / "mismatched.ssmnet";
    writeBytes(mismatched, other_dim);
    expectFileError([&] { loadNet(mismatched); }, mismatched, "do not match");

    std::string flipped = bytes;
    flipped[bytes.size() - 3] ^= 0x10;  // inside the last weight
    const auto corrupt = dir / "corrupt.ssmnet";
    writeBytes(corrupt, flipped);
    expectFileError([&] { loadNet(corrupt); }, corrupt, "fingerprint");
  }
  const auto cnn = dir / (descriptorName(DescriptorKind::kSegMapCnn) + ".ssmnet");
  expectFileError([&] { loadNet(cnn, DescriptorKind::kSemSegMapNet); }, cnn,
                  "expected semsegmap-net");
  expectFileError([&] { loadNet(dir / "missing.ssmnet"); }, dir / "missing.ssmnet", "cannot open");
  // A network of another kind is refused by the describer too.
  EXPECT_THROW(makeLearnedDescriber(DescriptorKind::kSemSegMapNet,
                                    {loadNet(cnn, DescriptorKind::kSegMapCnn), 1}),
               std::invalid_argument);
  std::filesystem::remove_all(dir);
}

// The set abstraction is in the model file (format version 2) and in the fingerprint: an edited
// radius is another model, while the models of version 1, trained with the defaults, keep their
// fingerprints and so the maps built with them.
TEST(ModelFile, SetAbstractionIsRecordedAndFingerprinted) {
  const auto dir = tempDir();
  torch::manual_seed(4);
  NetConfig config = tinyConfig(DescriptorKind::kSemSegMapNet);
  const auto net = makeNet(config);
  config.sa1_radius = 0.25f;
  config.sa_neighbours = 8;
  torch::manual_seed(4);
  const auto edited = makeNet(config);  // the same weights, another grouping
  EXPECT_NE(netFingerprint(*edited), netFingerprint(*net));
  const auto path = dir / "edited.ssmnet";
  saveNet(path, *edited);
  const Model model = readModelFile(path);
  EXPECT_FLOAT_EQ(model.config.sa1_radius, 0.25f);
  EXPECT_EQ(model.config.sa_neighbours, 8);
  EXPECT_EQ(loadNet(path)->config().sa_neighbours, 8);
  NetConfig bad = config;
  bad.sa2_divisor = 3;  // num_points is no multiple of it
  EXPECT_THROW(validateNetConfig(bad), std::invalid_argument);
  std::filesystem::remove_all(dir);
}

// A LiDAR-only model sees every point without colour and as of class unknown, whatever the data
// carries; the file records it, and the fingerprint tells it from the same weights with both.
TEST(ModelFile, ModalitiesAreRecordedFingerprintedAndApplied) {
  const auto dir = tempDir();
  NetConfig config = tinyConfig(DescriptorKind::kSemSegMapNet);
  torch::manual_seed(5);
  const auto net = makeNet(config);
  config.use_color = config.use_classes = false;
  torch::manual_seed(5);
  const auto lidar = makeNet(config);
  EXPECT_NE(netFingerprint(*lidar), netFingerprint(*net));
  const auto path = dir / "lidar.ssmnet";
  saveNet(path, *lidar);
  EXPECT_EQ(readBytes(path)[6], 4) << "format version 3 on records the modalities";
  const Model model = readModelFile(path);
  EXPECT_FALSE(model.config.use_color);
  EXPECT_FALSE(model.config.use_classes);
  EXPECT_EQ(netFingerprint(*netFromModel(model)), netFingerprint(*lidar));

  const EnrichedCloud car = makeShape(0, 300, 1);  // coloured points of class car
  const NetInput with = makeNetInput(net->config(), {&car}, {7});
  const NetInput without = makeNetInput(config, {&car}, {7});
  EXPECT_GT(with.points.narrow(2, 3, 3).abs().sum().item<float>(), 1.0f);
  EXPECT_EQ(without.points.narrow(2, 3, 3).abs().sum().item<float>(), 0.0f);
  EXPECT_GT(with.class_grid[0][cls::kCar].sum().item<float>(), 0.0f);
  EXPECT_EQ(without.class_grid[0][cls::kCar].sum().item<float>(), 0.0f);
  EXPECT_NEAR(without.class_grid[0][cls::kUnknown].sum().item<float>(),
              with.class_grid[0][cls::kCar].sum().item<float>(), 1e-4);
  EXPECT_TRUE(torch::equal(with.points.narrow(2, 0, 3), without.points.narrow(2, 0, 3)));
  std::filesystem::remove_all(dir);
}

// The shapes a configuration implies, without torch (net_config.h), are those of the networks.
TEST(ModelFile, TensorShapesOfAConfigurationAreThoseOfItsNetwork) {
  std::vector<NetConfig> configs;
  for (const DescriptorKind kind :
       {DescriptorKind::kSemSegMapNet, DescriptorKind::kSegMapCnn, DescriptorKind::kSmoothNetBow}) {
    configs.push_back(tinyConfig(kind));
    NetConfig other = tinyConfig(kind);
    other.smoothnet_voxels = 8;
    other.smoothnet_width = 3;
    other.smoothnet_local_dim = 5;
    other.recon_grid = 32;
    other.pointnet_width = 3;
    other.cnn_width = 5;
    other.grid_xy = 16;
    other.num_classes = 7;
    configs.push_back(other);
  }
  configs.push_back(NetConfig{});
  for (const NetConfig& config : configs) {
    const Model model = modelOf(*makeNet(config));
    const std::vector<TensorShape> shapes = netTensorShapes(config);
    ASSERT_EQ(shapes.size(), model.tensors.size()) << descriptorName(config.kind);
    for (size_t i = 0; i < shapes.size(); ++i) {
      EXPECT_EQ(shapes[i].name, model.tensors[i].name);
      EXPECT_EQ(shapes[i].shape, model.tensors[i].shape) << shapes[i].name;
      EXPECT_EQ(shapes[i].numel(), model.tensors[i].values.size()) << shapes[i].name;
    }
  }
}

namespace {

// A model file's header (artefacts/model_file.h, version 3) for `config`, then `tensor_count`, and
// no tensors: what a corrupt or truncated file starts with.
std::string modelHeader(const NetConfig& c, uint64_t tensor_count) {
  BinaryWriter w;
  w.putBytes("SSMNET", 6);
  w.put<uint32_t>(3);
  w.putString32(descriptorName(c.kind));
  for (const int32_t f :
       {c.descriptor_dim, c.num_points, c.num_classes, c.grid_xy, c.grid_z, c.recon_grid,
        c.pointnet_width, c.cnn_width, c.sa1_divisor, c.sa2_divisor, c.sa_neighbours})
    w.put(f);
  w.put(c.sa1_radius);
  w.put(c.sa2_radius);
  w.put<uint8_t>(1);
  w.put<uint8_t>(1);
  w.putBytes("0123456789abcdef", 16);
  w.put(tensor_count);
  return w.take();
}

long peakRssKb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}

}  // namespace

// issue 18: a 72-byte model file built the whole network of its header (3.3 GB, 24 s) before
// the file was known to be too short. Now the header's ranges, the tensor count and every tensor's
// name and shape are checked against the file before a tensor is allocated or a network built.
TEST(ModelFile, OversizedOrShortHeadersAreRefusedBeforeAnythingIsBuilt) {
  const auto dir = tempDir();
  const auto path = dir / "hostile.ssmnet";
  NetConfig largest;  // every width at its limit: ~10^8 parameters, were it built
  largest.descriptor_dim = 1024;
  largest.num_points = 16384;
  largest.pointnet_width = 256;
  largest.recon_grid = 64;
  const long rss_before = peakRssKb();
  const auto start = std::chrono::steady_clock::now();
  const size_t expected_tensors = netTensorShapes(largest).size();
  writeBytes(path, modelHeader(largest, 0));
  expectFileError([&] { loadNet(path); }, path, "0 tensors in the file");
  writeBytes(path, modelHeader(largest, expected_tensors));
  expectFileError([&] { loadNet(path); }, path, "does not fit in the rest of the file");
  // The tensors' count fits, but the first tensor's shape is not the configuration's.
  BinaryWriter tensor;
  tensor.putString32("sa1.0.weight");
  tensor.put<uint32_t>(4);
  for (const int64_t s : {int64_t{1} << 30, int64_t{6}, int64_t{1}, int64_t{1}}) tensor.put(s);
  writeBytes(path,
             modelHeader(largest, expected_tensors) + tensor.bytes() + std::string(1024, '\0'));
  expectFileError([&] { loadNet(path); }, path, "[256, 6, 1, 1] expected");
  // The config's values are limited before any shape is computed from them.
  NetConfig too_wide = largest;
  too_wide.pointnet_width = 1 << 20;
  writeBytes(path, modelHeader(too_wide, 40));
  expectFileError([&] { loadNet(path); }, path, "corrupt header: NetConfig.pointnet_width");
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 2.0);
  EXPECT_LT(peakRssKb() - rss_before, 100 * 1024) << "KB more at the peak";
  std::filesystem::remove_all(dir);
}

TEST(ModelFile, NonFiniteWeightsAreRefused) {
  const auto dir = tempDir();
  const NetConfig config = tinyConfig(DescriptorKind::kSegMapCnn);
  Model model = modelOf(*makeNet(config));
  model.tensors[3].values[2] = std::numeric_limits<float>::quiet_NaN();
  const auto path = dir / "nan.ssmnet";
  writeModelFile(path, model);
  expectFileError([&] { readModelFile(path); }, path,
                  "corrupt weights: tensor " + model.tensors[3].name);
  std::filesystem::remove_all(dir);
}

TEST(ModelFile, ShippedVersionOneModelsLoadWithTheirFingerprints) {
  for (const char* name : {"semsegmap-net", "segmap-cnn"}) {
    const auto path =
        std::filesystem::path(SEMSEGMAP_SOURCE_DIR) / "models" / (name + std::string(".model"));
    const std::string bytes = readBytes(path);
    ASSERT_GT(bytes.size(), 10u);
    SCOPED_TRACE(name);
    EXPECT_EQ(bytes[6], 1) << "the shipped models were written in format version 1";
    const Model model = readModelFile(path);
    EXPECT_EQ(model.config.sa1_divisor, 4);
    EXPECT_FLOAT_EQ(model.config.sa2_radius, 0.4f);
    const auto net = netFromModel(model);  // checks the stored fingerprint
    EXPECT_EQ(netFingerprint(*net), model.fingerprint);
  }
}

// ---- inference ---------------------------------------------------------------------------------

TEST(LearnedDescriber, RepeatableAndIndependentOfPointOrderAndBatch) {
  const auto dir = tempDir();
  std::vector<EnrichedCloud> segments;
  for (int i = 0; i < 70; ++i) segments.push_back(makeShape(i % 4, 150 + 40 * i, 100 + i));
  for (const DescriptorKind kind : {DescriptorKind::kSemSegMapNet, DescriptorKind::kSegMapCnn}) {
    SCOPED_TRACE(descriptorName(kind));
    torch::manual_seed(3);
    NetConfig config;
    config.kind = kind;
    const auto net = makeNet(config);
    const auto path = dir / "model.ssmnet";
    saveNet(path, *net);
    const auto describer = makeLearnedDescriber(kind, {loadNet(path, kind), 2});
    EXPECT_EQ(describer->kind(), kind);
    EXPECT_EQ(describer->dimension(), config.descriptor_dim);
    EXPECT_EQ(describer->fingerprint(), netFingerprint(*net));

    std::vector<DescriptorInput> batch;
    for (const EnrichedCloud& s : segments) batch.push_back({&s});
    const Eigen::MatrixXf all = describer->describe(batch);  // two chunks
    ASSERT_EQ(all.rows(), 70);
    EXPECT_TRUE(all.allFinite());
    EXPECT_EQ(describer->describe(batch), all);  // repeatable
    EXPECT_EQ(describer->describe({}).rows(), 0);

    for (const size_t i : {3u, 66u}) {
      EnrichedCloud shuffled = segments[i];
      std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(static_cast<uint32_t>(i)));
      const Eigen::MatrixXf alone = describer->describe({{&segments[i]}});
      const Eigen::MatrixXf reordered = describer->describe({{&shuffled}});
      EXPECT_LE((alone - reordered).cwiseAbs().maxCoeff(), 1e-5f) << "segment " << i;
      // Batch composition changes only floating-point rounding.
      EXPECT_LE((alone.row(0) - all.row(static_cast<Eigen::Index>(i))).cwiseAbs().maxCoeff(), 1e-4f)
          << "segment " << i;
    }
    EXPECT_THROW(describer->describe({{nullptr}}), std::invalid_argument);
  }
  std::filesystem::remove_all(dir);
}

TEST(SegMapGrid, YawAndTranslationInvariant) {
  const EnrichedCloud wall = makeShape(4, 2500, 7);
  const OccupancyGridSample reference = makeSegMapGrid(wall, 32, 16);
  const double occupied = std::count(reference.occupancy.begin(), reference.occupancy.end(), 1.0f);
  ASSERT_GT(occupied, 100);
  const double yaw0 = principalYaw(wall);

  torch::manual_seed(4);
  NetConfig config;
  config.kind = DescriptorKind::kSegMapCnn;
  const auto net = makeNet(config);
  net->eval();
  torch::NoGradGuard no_grad;
  const auto describe = [&](const EnrichedCloud& c) {
    return net->encode(makeNetInput(config, {&c}, std::vector<uint64_t>{0}));
  };
  const torch::Tensor d0 = describe(wall);

  for (const double yaw : {0.3, 1.0, 2.5, -2.0, kPi, -0.5 * kPi}) {
    SCOPED_TRACE(yaw);
    const EnrichedCloud moved = transformed(wall, yaw, {12.5, -7.25, 0.8});
    const double expected = std::remainder(yaw0 + yaw, 2 * kPi);
    EXPECT_NEAR(std::remainder(principalYaw(moved) - expected, 2 * kPi), 0.0, 1e-5);
    const OccupancyGridSample grid = makeSegMapGrid(moved, 32, 16);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(grid.extent_m[a], reference.extent_m[a], 1e-4);
    int differing = 0;
    for (size_t i = 0; i < grid.occupancy.size(); ++i) {
      differing += grid.occupancy[i] != reference.occupancy[i];
    }
    EXPECT_LE(differing, 0.02 * occupied);
    const torch::Tensor d = describe(moved);
    EXPECT_LE((d - d0).norm().item<float>(), 0.05f * d0.norm().item<float>());
  }
  // Without the alignment the grid would change: the wall turned by 90 degrees is not
  // the same set of voxels in an unaligned grid, so the test above is not vacuous.
  EXPECT_GT(std::abs(std::remainder(principalYaw(transformed(wall, 0.5 * kPi, {0, 0, 0})) - yaw0,
                                    2 * kPi)),
            1.0);
}

// ---- learning ----------------------------------------------------------------------------------

TEST(LearnedNet, TinyNetworkOverfitsAHandfulOfSegments) {
  for (const DescriptorKind kind : {DescriptorKind::kSemSegMapNet, DescriptorKind::kSegMapCnn}) {
    SCOPED_TRACE(descriptorName(kind));
    torch::manual_seed(5);
    const NetConfig config = tinyConfig(kind);
    // 4 instances x 2 observations: jittered, 15 % of the points dropped, another subsample.
    std::vector<EnrichedCloud> observations;
    for (int instance = 0; instance < 4; ++instance) {
      const EnrichedCloud shape = makeShape(instance, 800, 10 + instance);
      for (int obs = 0; obs < 2; ++obs) {
        std::mt19937 rng(static_cast<uint32_t>(100 * instance + obs));
        std::normal_distribution<float> jitter(0.0f, 0.02f);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        EnrichedCloud o;
        for (EnrichedPoint p : shape) {
          if (u(rng) < 0.15f) continue;
          p.x += jitter(rng), p.y += jitter(rng), p.z += jitter(rng);
          o.push_back(p);
        }
        observations.push_back(o);
      }
    }
    std::vector<const EnrichedCloud*> ptrs;
    for (const EnrichedCloud& o : observations) ptrs.push_back(&o);
    const NetInput in = makeNetInput(config, ptrs, std::vector<uint64_t>{1, 2, 3, 4, 5, 6, 7, 8});

    // Every (anchor, positive, negative) with the anchor in either observation.
    std::vector<int64_t> a, p, n;
    for (int i = 0; i < 8; ++i) {
      for (int j = 0; j < 8; ++j) {
        if (j / 2 == i / 2) continue;
        a.push_back(i), p.push_back(i ^ 1), n.push_back(j);
      }
    }
    const torch::Tensor ia = torch::tensor(a), ip = torch::tensor(p), ineg = torch::tensor(n);
    const torch::Tensor sigma = in.n_points.index_select(0, ip) / in.n_points.index_select(0, ia);

    const auto net = makeNet(config);
    torch::optim::Adam adam(net->parameters(), torch::optim::AdamOptions(3e-3));
    float first = 0, last = 0;
    for (int step = 0; step < 150; ++step) {
      const torch::Tensor d = net->encode(in);
      const torch::Tensor loss =
          tripletLoss(d.index_select(0, ia), d.index_select(0, ip), d.index_select(0, ineg), sigma);
      adam.zero_grad();
      loss.backward();
      adam.step();
      (step == 0 ? first : last) = loss.item<float>();
    }
    EXPECT_GT(first, 0.1f);
    EXPECT_LT(last, 0.05f * first);

    torch::NoGradGuard no_grad;
    const torch::Tensor dist = pairwiseDistances(net->encode(in));
    for (int i = 0; i < 8; ++i) {
      for (int j = 0; j < 8; ++j) {
        if (j / 2 == i / 2) continue;
        EXPECT_LT(dist[i][i ^ 1].item<float>(), dist[i][j].item<float>())
            << "anchor " << i << " negative " << j;
      }
    }
  }
}
