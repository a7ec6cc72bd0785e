// semsegmap simulate: renders a run of the built-in simulator into a dataset directory.
#include <iostream>

#include "cli_args.h"
#include "progress.h"
#include "semsegmap/io/dataset_writer.h"
#include "semsegmap/sim/simulator.h"

namespace semsegmap::app {

int runSimulate(const std::vector<std::string>& args) {
  const CliArgs a(args,
                  {"world-seed", "run", "condition", "traffic-seed", "max-frames", "world", "out"},
                  {"no-cameras"});
  sim::SimConfig config;
  config.world =
      sim::worldPreset(a.get("world", "full"), static_cast<uint64_t>(a.getInt("world-seed", 1)));
  config.run = sim::parseRun(a.require("run"));
  config.condition = a.get("condition", "");
  if (a.has("traffic-seed"))
    config.traffic_seed = static_cast<uint64_t>(a.getInt("traffic-seed", 1));
  const long long max_frames = a.getInt("max-frames", 0);
  if (max_frames < 0) throw std::invalid_argument("--max-frames must not be negative");
  config.max_frames = static_cast<size_t>(max_frames);
  config.render_cameras = !a.has("no-cameras");
  const std::string out = a.require("out");

  sim::Simulator simulator(config);
  DatasetWriter writer(out, simulator.info());
  Progress progress("simulate " + sim::runName(config.run), simulator.size());
  for (size_t i = 0; i < simulator.size(); ++i) {
    writer.write(simulator.frame(i));
    progress.update(i + 1);
  }
  std::cout << "wrote " << writer.framesWritten() << " frames (" << simulator.trajectory().length_m
            << " m, " << simulator.lighting().name << ", traffic seed " << simulator.trafficSeed()
            << ") to " << out << "\n";
  return 0;
}

}  // namespace semsegmap::app
