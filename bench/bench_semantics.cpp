// The segmentation network stage on the CPU: one 640x480 picture through a MobileNet-class
// encoder-decoder (scripts/make_onnx_models.py: MobileNet-v1 depthwise-separable blocks to 1/16,
// a decoder to 1/8 with a skip connection, 19 classes, seeded random weights: realistic cost,
// meaningless labels), with preprocessing, bilinear upsampling of the logits and the class map.
// Arg: OpenCV's threads.
#include <benchmark/benchmark.h>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/semantics/segmentation_network.h"
#include "semsegmap/settings/config.h"

using namespace semsegmap;

namespace {

ClassMap nineteenClasses() {
  std::vector<ClassMapEntry> entries;
  for (int c = 0; c < 19; ++c) entries.push_back({c, "class" + std::to_string(c), cls::kBuilding});
  return ClassMap("nineteen", entries);
}

void BM_SegmentationNetwork(benchmark::State& state) {
  SemanticsConfig config;
  config.model = std::string(SEMSEGMAP_ONNX_DIR) + "/mobilenet_seg.onnx";
  config.threads = static_cast<int>(state.range(0));
  SegmentationNetwork network(config, readFileBytes(config.model), nineteenClasses(), config.model);
  Image picture(640, 480, 3);
  uint32_t seed = 7;
  for (uint8_t& v : picture.data)
    v = static_cast<uint8_t>((seed = seed * 1664525u + 1013904223u) >> 24);
  network.check(640, 480);  // the first run allocates
  for (auto _ : state) benchmark::DoNotOptimize(network.label(picture, "picture").data.data());
  state.counters["Hz"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SegmentationNetwork)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);

// The shipped network (models/semsegmap-seg.onnx, trained on the simulator) as
// config/semantics-sim-network.yaml runs it: a 640x480 picture shrunk to the file's input size,
// logits at half of it upsampled back. Arg: OpenCV's threads.
void BM_ShippedSegmentationNetwork(benchmark::State& state) {
  SemanticsConfig config =
      loadSemanticsConfig(std::string(SEMSEGMAP_SOURCE_DIR) + "/config/semantics-sim-network.yaml");
  config.threads = static_cast<int>(state.range(0));
  SegmentationNetwork network(config, readFileBytes(config.model),
                              ClassMap::Identity(ClassTable::Default()), config.model);
  Image picture(640, 480, 3);
  uint32_t seed = 7;
  for (uint8_t& v : picture.data)
    v = static_cast<uint8_t>((seed = seed * 1664525u + 1013904223u) >> 24);
  network.check(640, 480);
  for (auto _ : state) benchmark::DoNotOptimize(network.label(picture, "picture").data.data());
  state.counters["Hz"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ShippedSegmentationNetwork)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(3.0);

}  // namespace
