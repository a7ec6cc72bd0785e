// semsegmap: the command line. Each subcommand lives in its own cmd_*.cpp; errors become one
// line on stderr and a non-zero exit.
#include <cstring>
#include <exception>
#include <functional>
#include <iostream>
#include <map>

#include "cli_args.h"

namespace {

const char* kUsage = R"(usage: semsegmap <command> [options]

commands:
  simulate           --world-seed N --run S0|S1|S2|S3 [--condition sunny|sunrise]
                     [--traffic-seed M] [--max-frames K] [--world full|small|tiny] --out DIR
  simulate-overview  --world-seed N [--world full|small|tiny] --out FILE.png
                     [--cameras FILE.png] [--run S2] [--frame I]
  enrich             --dataset SPEC [--frame I] --out FILE.png [--ply FILE.ply] [--camera K]
                     LiDAR points coloured from the cameras, drawn over camera K
  convert            --dataset SPEC --out DIR [--max-frames K]
                     any dataset written in the project's format
  segment            --dataset SPEC --config FILE --out DIR [--poses gt|odom] [--max-frames K]
                     enrichment + local map + incremental segmentation -> segments.csv/.ply/.png
  map                --dataset SPEC --config FILE --out MAP [--poses gt|odom|slam]
                     [--max-frames K] [--points N] [--float32]
                     builds and saves a target map (N picture points per segment, default 0)
  localize           --dataset SPEC --config FILE --map MAP --out DIR [--max-frames K]
                     localizes a run against a target map -> localizations.csv, summary.json,
                     localization.png
  slam               --dataset SPEC --config FILE --out DIR [--max-frames K]
                     mapping with loop closure on odometry -> trajectory_{tum,kitti}.txt,
                     loops.csv, summary.json, slam.png
  train              --descriptor semsegmap-net|segmap-cnn --dataset SPEC[,SPEC...] --out FILE
                     [--epochs N] [--batch N] [--threads N] [--config FILE] [--max-frames K]
                     [--cache FILE] [--anchors-per-epoch N] [--lr X] [--seed N] [--points N]
                     [--history FILE.csv]
                     trains a learned descriptor on simulated ground truth; a key=value after
                     a sim: spec belongs to it, any other item starts a new spec (';' also
                     separates): sim:world=1,run=S1,sim:world=1,run=S1,condition=sunrise
  eval segmentation  --world-seed N --out DIR [--preset full|small|tiny] [--max-frames K]
                     [--configs A.yaml,B.yaml] [--segmentation-run S1]
                     convex hull IoU of segments at revisits, first config against the second
                     -> segmentation.json, segmentation.png
  eval descriptors   --world-seed N --out DIR [--preset ...] [--descriptor-run S0]
                     [--max-frames K] [--config FILE] [--models DIR] [--descriptors LIST]
                     rank of each segment's final observation for its earlier ones, per
                     completeness band, for each descriptor -> descriptors.json, .png
  eval localization  --world-seed N --out DIR [--preset ...] [--max-frames K]
                     [--configs A.yaml,B.yaml] [--map-run S0] [--query-runs S2,S3]
                     map one run, localize the others with every config -> localization.json,
                     localization_accuracy.png, maps/, one folder per run and config
  eval paper         --world-seed N --out DIR [all of the above]
                     the three experiments and report.md
  demo               [--out DIR] [--world-seed N] [--preset small] [--max-frames K]
                     the main job: map S0, localize S2 and S3 with SemSegMap and SegMap on
                     the small world -> table, report.md and pictures in DIR

datasets (SPEC): DIR (project format), kitti-raw:PATH, semantickitti:PATH, nclt:PATH,
                 sim:world=N,run=S0..S3[,condition=sunrise][,traffic=M][,frames=K][,preset=small]

run 'semsegmap <command> --help' for a command's options.
)";

}  // namespace

int main(int argc, char** argv) {
  using Command = std::function<int(const std::vector<std::string>&)>;
  const std::map<std::string, Command> commands = {
      {"simulate", semsegmap::app::runSimulate},
      {"simulate-overview", semsegmap::app::runSimulateOverview},
      {"enrich", semsegmap::app::runEnrich},
      {"convert", semsegmap::app::runConvert},
      {"segment", semsegmap::app::runSegment},
      {"map", semsegmap::app::runMap},
      {"localize", semsegmap::app::runLocalize},
      {"slam", semsegmap::app::runSlam},
      {"train", semsegmap::app::runTrain},
      {"eval", semsegmap::app::runEval},
      {"demo", semsegmap::app::runDemo},
  };
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    std::cout << kUsage;
    return argc < 2 ? 2 : 0;
  }
  auto it = commands.find(argv[1]);
  if (it == commands.end()) {
    std::cerr << "semsegmap: unknown command '" << argv[1] << "'\n" << kUsage;
    return 2;
  }
  std::vector<std::string> args(argv + 2, argv + argc);
  for (const auto& a : args)
    if (a == "--help" || a == "-h") {
      std::cout << kUsage;
      return 0;
    }
  try {
    return it->second(args);
  } catch (const std::exception& e) {
    std::cerr << "semsegmap " << argv[1] << ": error: " << e.what() << "\n";
    return 1;
  }
}
