// semsegmap simulate-overview: the bird's-eye picture of a world with its runs, and optionally a
// contact sheet of one frame's cameras, labels and LiDAR.
#include <iostream>

#include "cli_args.h"
#include "semsegmap/viz/sim_overview.h"

namespace semsegmap::app {

int runSimulateOverview(const std::vector<std::string>& args) {
  const CliArgs a(args, {"world-seed", "world", "out", "cameras", "run", "frame"}, {});
  const sim::WorldConfig world =
      sim::worldPreset(a.get("world", "full"), static_cast<uint64_t>(a.getInt("world-seed", 1)));
  const std::string out = a.require("out");
  viz::writeSimOverview(world, out);
  std::cout << "wrote " << out << "\n";
  if (a.has("cameras")) {
    const long long frame = a.getInt("frame", 40);
    if (frame < 0) throw std::invalid_argument("--frame must not be negative");
    viz::writeCameraContactSheet(world, sim::parseRun(a.get("run", "S2")),
                                 static_cast<size_t>(frame), a.get("cameras", ""));
    std::cout << "wrote " << a.get("cameras", "") << "\n";
  }
  return 0;
}

}  // namespace semsegmap::app
