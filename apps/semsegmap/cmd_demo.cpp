// semsegmap demo: the main job on simulated data. For now it builds the demo world, renders it
// and writes the overview and a camera contact sheet; mapping and localization join as they land.
#include <filesystem>
#include <iostream>

#include "cli_args.h"
#include "progress.h"
#include "semsegmap/sim/simulator.h"
#include "semsegmap/viz/sim_overview.h"

namespace semsegmap::app {

int runDemo(const std::vector<std::string>& args) {
  const CliArgs a(args, {"out", "world-seed"}, {});
  const std::filesystem::path out = a.get("out", "demo_out");
  std::filesystem::create_directories(out);
  const sim::WorldConfig world =
      sim::worldPreset("small", static_cast<uint64_t>(a.getInt("world-seed", 1)));

  viz::writeSimOverview(world, out / "overview.png");
  viz::writeCameraContactSheet(world, sim::Run::S2, 40, out / "cameras.png");

  std::cout << "run  condition  frames  length_m  points/frame  ms/frame\n";
  for (sim::Run run : {sim::Run::S0, sim::Run::S1, sim::Run::S2, sim::Run::S3}) {
    sim::SimConfig c;
    c.world = world;
    c.run = run;
    sim::Simulator simulator(c);
    // A handful of frames per run shows the rendering rate without the demo taking minutes.
    const size_t n = std::min<size_t>(10, simulator.size());
    Progress progress("render " + sim::runName(run), n);
    size_t points = 0;
    for (size_t i = 0; i < n; ++i) {
      points += simulator.frame(i * (simulator.size() / n)).points.size();
      progress.update(i + 1);
    }
    std::printf("%-4s %-10s %6zu  %8.0f  %12zu  %8.0f\n", sim::runName(run).c_str(),
                simulator.lighting().name.c_str(), simulator.size(),
                simulator.trajectory().length_m, points / n, 1000.0 * progress.seconds() / n);
  }
  std::cout << "pictures: " << (out / "overview.png").string() << ", "
            << (out / "cameras.png").string() << "\n";
  return 0;
}

}  // namespace semsegmap::app
