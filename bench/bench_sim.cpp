// Simulator throughput: one frame at the paper's rig (LiDAR 1920 x 64 + three 640 x 480 cameras
// with shadow rays) in the full world. Target: at most 150 ms a frame on 2 cores.
#include <benchmark/benchmark.h>

#include "semsegmap/sim/camera_sim.h"
#include "semsegmap/sim/lidar_sim.h"
#include "semsegmap/sim/simulator.h"

using namespace semsegmap;

namespace {

sim::Simulator& fullSimulator() {
  static sim::Simulator s([] {
    sim::SimConfig c;
    c.run = sim::Run::S2;
    return c;
  }());
  return s;
}

void BM_SimulateFrame(benchmark::State& state) {
  auto& s = fullSimulator();
  size_t i = 0;
  for (auto _ : state) {
    Frame f = s.frame((i += 37) % s.size());
    benchmark::DoNotOptimize(f.points.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SimulateFrame)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(5.0);

void BM_Lidar(benchmark::State& state) {
  auto& s = fullSimulator();
  const Pose T = s.trajectory().T_world_base[50] * s.info().rig.T_base_lidar;
  for (auto _ : state) {
    auto scan = sim::simulateLidar(s.scene(), s.info().rig.lidar, T, 1);
    benchmark::DoNotOptimize(scan.points.data());
  }
}
BENCHMARK(BM_Lidar)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Camera(benchmark::State& state) {
  auto& s = fullSimulator();
  const auto& cam = s.info().rig.cameras[1];
  const Pose T =
      s.trajectory().T_world_base[50] * s.info().rig.T_base_lidar * cam.T_camera_lidar.inverse();
  for (auto _ : state) {
    auto r = sim::renderCamera(s.scene(), cam, T, s.lighting(), 1);
    benchmark::DoNotOptimize(r.rgb.data.data());
  }
}
BENCHMARK(BM_Camera)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
