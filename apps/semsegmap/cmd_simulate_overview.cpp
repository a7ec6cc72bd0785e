// semsegmap simulate-overview: the bird's-eye picture of a world with its runs, and optionally a
// contact sheet of one frame's cameras, labels and LiDAR.
#include <iostream>

#include "cli_args.h"
#include "semsegmap/viz/sim_overview.h"

namespace semsegmap::app {

namespace {

int runSimulateOverview(const CliArgs& a) {
  const sim::WorldConfig world = sim::worldPreset(a.get("world"), a.getCount("world-seed"));
  const std::string out = a.get("out");
  viz::writeSimOverview(world, out);
  std::cout << "wrote " << out << "\n";
  if (a.has("cameras")) {
    viz::writeCameraContactSheet(world, sim::parseRun(a.get("run")), a.getCount("frame"),
                                 a.get("cameras"));
    std::cout << "wrote " << a.get("cameras") << "\n";
  }
  return 0;
}

}  // namespace

const CommandSpec& simulateOverviewCommand() {
  static const CommandSpec command{
      "simulate-overview",
      "bird's-eye picture of a world with its runs, and a contact sheet of one frame",
      {
          {"world-seed", Value::kCount, "N", "1", "seed of the procedural world"},
          {"world", Value::kText, "full|small|tiny", "full", "size of the world"},
          {"out", Value::kText, "FILE.png", "", "the bird's-eye picture to write", kRequired},
          {"cameras", Value::kText, "FILE.png", "",
           "also write a contact sheet of one frame: cameras, labels and LiDAR"},
          {"run", Value::kText, "S0|S1|S2|S3", "S2", "the run of the contact sheet"},
          {"frame", Value::kCount, "I", "40", "the frame of the contact sheet"},
      },
      "",
      runSimulateOverview};
  return command;
}

}  // namespace semsegmap::app
