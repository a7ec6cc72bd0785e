// semsegmap simulate: renders a run of the built-in simulator into a dataset directory.
#include <iostream>

#include "cli_args.h"
#include "interrupt.h"
#include "progress.h"
#include "semsegmap/io/dataset_writer.h"
#include "semsegmap/sim/simulator.h"

namespace semsegmap::app {

namespace {

int runSimulate(const CliArgs& a) {
  sim::SimConfig config;
  config.world = sim::worldPreset(a.get("world"), a.getCount("world-seed"));
  config.run = sim::parseRun(a.get("run"));
  if (a.has("condition")) config.condition = a.get("condition");
  if (a.has("traffic-seed")) config.traffic_seed = a.getCount("traffic-seed");
  config.max_frames = a.frameLimit();
  config.render_cameras = !a.has("no-cameras");
  const std::string out = a.get("out");

  sim::Simulator simulator(config);
  DatasetWriter writer(out, simulator.info());
  Progress progress("simulate " + sim::runName(config.run), simulator.size());
  // As convert: a stopped run is a readable dataset of the frames written.
  for (size_t i = 0; i < simulator.size() && !stopRequested(); ++i) {
    writer.write(simulator.frame(i));
    progress.update(i + 1);
  }
  std::cout << "wrote " << writer.framesWritten() << " frames (" << simulator.trajectory().length_m
            << " m, " << simulator.lighting().name << ", traffic seed " << simulator.trafficSeed()
            << ") to " << out << "\n";
  if (writer.framesWritten() < simulator.size())
    return interruptedRun("simulate", writer.framesWritten(), simulator.size(), out);
  return 0;
}

}  // namespace

const CommandSpec& simulateCommand() {
  static const CommandSpec command{
      "simulate",
      "renders a run of the built-in simulator into a dataset directory",
      {
          {"world-seed", Value::kCount, "N", "1", "seed of the procedural world"},
          {"run", Value::kText, "S0|S1|S2|S3", "", "the run to drive", kRequired},
          {"condition", Value::kText, "sunny|sunrise", "",
           "lighting (default: the run's own, sunrise for S3, sunny for the others)"},
          {"traffic-seed", Value::kCount, "M", "",
           "seed of the parked and moving traffic (default: one per run)"},
          maxFramesOption(),
          {"world", Value::kText, "full|small|tiny", "full", "size of the world"},
          {"out", Value::kText, "DIR", "", "dataset directory to write", kRequired},
          {"no-cameras", Value::kFlag, "", "", "LiDAR only: do not render the cameras"},
      },
      "",
      runSimulate,
      /*stops_between_frames=*/true};
  return command;
}

}  // namespace semsegmap::app
