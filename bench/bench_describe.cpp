// Learned descriptor inference, batched, on synthetic segments of simulated size (500-3000
// points: boxes, walls, trunks, crowns with colours and classes). Targets on 2 cores:
// semsegmap-net >= 300 segments/s, segmap-cnn >= 1000 segments/s (items_per_second); 3dsmoothnet
// is a baseline of retrieval, without a target: its time is reported.
// Randomly initialised weights: the speed does not depend on their values.
#include <benchmark/benchmark.h>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <random>

#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/describe/learned_describer.h"
#include "semsegmap/describe/learned_net.h"
#include "semsegmap/describe/smoothnet.h"

using namespace semsegmap;

namespace {

EnrichedCloud syntheticSegment(int index) {
  std::mt19937 rng(static_cast<uint32_t>(index));
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::normal_distribution<float> g(0.0f, 1.0f);
  const int n = 500 + static_cast<int>(u(rng) * 2500);
  const int shape = index % 4;
  const float size = 0.5f + 4.0f * u(rng);
  EnrichedCloud cloud(static_cast<size_t>(n));
  for (EnrichedPoint& p : cloud) {
    p.has_color = u(rng) < 0.9f;
    p.h = u(rng), p.s = u(rng), p.v = u(rng);
    switch (shape) {
      case 0:  // box surface
        p.x = size * u(rng), p.y = 0.6f * size * u(rng), p.z = size * (u(rng) < 0.5f ? 0 : 1);
        p.class_id = cls::kCar;
        break;
      case 1:  // wall
        p.x = 3 * size * u(rng), p.y = 0.1f * u(rng), p.z = size * u(rng);
        p.class_id = cls::kBuilding;
        break;
      case 2: {  // trunk
        const float a = 6.2831853f * u(rng);
        p.x = 0.3f * std::cos(a), p.y = 0.3f * std::sin(a), p.z = 2 * size * u(rng);
        p.class_id = cls::kTrunk;
        break;
      }
      default:  // crown
        p.x = size * g(rng), p.y = size * g(rng), p.z = 0.5f * size * g(rng);
        p.class_id = cls::kVegetation;
        break;
    }
    p.x += 100.0f, p.y -= 50.0f;  // map frame, away from the origin
  }
  return cloud;
}

const std::vector<EnrichedCloud>& segments() {
  static const std::vector<EnrichedCloud> s = [] {
    std::vector<EnrichedCloud> out;
    for (int i = 0; i < 256; ++i) out.push_back(syntheticSegment(i));
    return out;
  }();
  return s;
}

// Model files of the default configuration, one per kind, removed at exit.
struct TemporaryModels {
  std::vector<std::filesystem::path> paths;
  ~TemporaryModels() {
    std::error_code ignored;
    for (const auto& path : paths) std::filesystem::remove(path, ignored);
  }
};

std::string modelFile(DescriptorKind kind) {
  static TemporaryModels models;
  const auto path =
      std::filesystem::temp_directory_path() /
      ("semsegmap_bench_" + descriptorName(kind) + "_" + std::to_string(::getpid()) + ".ssmnet");
  if (!std::filesystem::exists(path)) {
    NetConfig config;
    config.kind = kind;
    if (kind == DescriptorKind::kSmoothNetBow) config.descriptor_dim = 16;  // its visual words
    torch::manual_seed(1);
    saveNet(path, *makeNet(config));
    models.paths.push_back(path);
  }
  return path.string();
}

// state.range(0): descriptor kind (2 segmap-cnn, 3 semsegmap-net, 4 3dsmoothnet); range(1):
// threads.
void BM_LearnedDescribe(benchmark::State& state) {
  const KeepOpenMpThreads keep;  // later benchmarks run OpenMP loops in this thread
  const auto kind = static_cast<DescriptorKind>(state.range(0));
  keepFreedMemoryForTorch();  // as the command line does at start-up
  const auto describer = makeLearnedDescriber(
      kind, {loadNet(modelFile(kind), kind), static_cast<int>(state.range(1))});
  std::vector<DescriptorInput> batch;
  for (const EnrichedCloud& s : segments()) batch.push_back({&s});
  for (auto _ : state) {
    Eigen::MatrixXf d = describer->describe(batch);
    benchmark::DoNotOptimize(d.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(batch.size()));
  state.SetLabel(descriptorName(kind));
}
BENCHMARK(BM_LearnedDescribe)
    ->ArgsProduct({{static_cast<int>(DescriptorKind::kSegMapCnn),
                    static_cast<int>(DescriptorKind::kSemSegMapNet),
                    static_cast<int>(DescriptorKind::kSmoothNetBow)},
                   {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The input preparation alone (subsampling, grids), single-threaded: its share of the above.
void BM_LearnedNetInput(benchmark::State& state) {
  // The benchmarks after it run OpenMP loops in this thread (learned_describer.h).
  const KeepOpenMpThreads keep;
  torch::set_num_threads(1);
  NetConfig config;
  config.kind = static_cast<DescriptorKind>(state.range(0));
  if (config.kind == DescriptorKind::kSmoothNetBow) config.descriptor_dim = 16;
  std::vector<const EnrichedCloud*> batch;
  for (const EnrichedCloud& s : segments()) batch.push_back(&s);
  const std::vector<uint64_t> salts(batch.size(), 1);
  for (auto _ : state) {
    NetInput in = makeNetInput(config, batch, salts);
    benchmark::DoNotOptimize(in.n_points.data_ptr<float>());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(batch.size()));
  state.SetLabel(descriptorName(config.kind));
}
BENCHMARK(BM_LearnedNetInput)
    ->Arg(static_cast<int>(DescriptorKind::kSegMapCnn))
    ->Arg(static_cast<int>(DescriptorKind::kSemSegMapNet))
    ->Arg(static_cast<int>(DescriptorKind::kSmoothNetBow))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

namespace {

// 3dsmoothnet's network alone on a batch of range(0) SDV grids, one thread: where its describing
// time goes.
void BM_SmoothNetLocal(benchmark::State& state) {
  const KeepOpenMpThreads keep;
  torch::set_num_threads(1);
  NetConfig config;
  config.kind = DescriptorKind::kSmoothNetBow;
  config.descriptor_dim = 16;
  torch::manual_seed(1);
  SmoothNetImpl net(config);
  net.eval();
  const torch::NoGradGuard no_grad;
  const torch::Tensor grids = torch::rand({state.range(0), 1, 16, 16, 16}) / 4096.0f;
  for (auto _ : state) {
    torch::Tensor d = net.local(grids);
    benchmark::DoNotOptimize(d.data_ptr<float>());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_SmoothNetLocal)
    ->Arg(32)
    ->Arg(64)
    ->Arg(256)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
