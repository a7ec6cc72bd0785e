// semsegmap eval revisits: how well the system localizes on a user's own recording. Maps some
// frames of any dataset with ground-truth poses, localizes others against them with each
// configuration, and writes the table, revisits.json and revisits.png. Built in every build:
// unlike the paper's experiments it needs no simulator.
#include <filesystem>
#include <iostream>

#include "cli_args.h"
#include "dataset_args.h"
#include "eval_args.h"
#include "interrupt.h"
#include "progress.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/eval/revisit_experiment.h"

namespace semsegmap::app {

namespace {

int runEvalRevisits(const CliArgs& a) {
  RevisitExperimentConfig c;
  try {
    c.map_frames = parseFrameRanges(a.get("map-frames"), "option --map-frames");
    c.query_frames = parseFrameRanges(a.get("query-frames"), "option --query-frames");
    if (a.has("wake-up")) parseWakeUp(a.get("wake-up"), "option --wake-up", c);
    c.check_ground_truth = a.has("check-ground-truth");
    if (a.get("scan-context") == "off") c.scan_context.reset();
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  c.place_radius_m = a.getNumber("place-radius");
  c.configs = comparedConfigs(a);
  for (const NamedConfig& config : c.configs)
    requireDescriberBuilt(config.config.descriptor, config.path.string());
  // LiDAR odometry and a segmentation network come from the first configuration's sections.
  const std::unique_ptr<FrameSource> source = openDatasetArg(a, c.configs.front().path);
  c.stop = stopToken();
  StageProgress progress;
  const std::filesystem::path out = a.get("out");
  const RevisitExperiment e = evaluateRevisits(*source, c, out, std::ref(progress));
  // Ctrl-C before the first frame: nothing worth keeping (main removes what the run made).
  if (e.interrupted && !progress.started()) return interruptedStages("eval revisits", progress, "");
  writeRevisitFiles(e, out);
  std::cout << revisitTable(e) << "wrote " << (out / "revisits.json").string()
            << ", revisits.png and one folder per configuration"
            << (c.scan_context ? " (and scan-context/)" : "") << "\n";
  return e.interrupted ? interruptedStages("eval revisits", progress, out.string()) : 0;
}

}  // namespace

const CommandSpec& evalRevisitsCommand() {
  static const CommandSpec revisits{
      "eval revisits",
      "maps some frames of a recording, localizes others against them -> revisits.json",
      datasetOptions(
          "a recording with ground-truth poses",
          {{"map-frames", Value::kText, "A:B[,C:D]", "",
            "frames the target map is built from (as the dataset lists them, from 0)", kRequired},
           {"query-frames", Value::kText, "E:F[,G:H]", "",
            "frames localized against it, on the dataset's odometry", kRequired},
           {"configs", Value::kText, "A.yaml,B.yaml",
            "config/lidar-camera.yaml,config/segmap-baseline.yaml",
            "the configurations compared (default: the shipped real-data ones)"},
           {"place-radius", Value::kNumber, "M", "10",
            "a query frame this close to a mapped frame is at a revisit"},
           {"check-ground-truth", Value::kFlag, "", "",
            "register each revisit scan to the mapped scans from its ground-truth pose: how far "
            "the ground truth disagrees with the map's geometry, and the errors against the "
            "registered poses"},
           {"wake-up", Value::kText, "N[/EVERY]", "",
            "the kidnapped robot: wake up at every EVERY-th query frame (default N) with an "
            "empty local map and localize from the N frames from there"},
           {"scan-context", Value::kText, "on|off", "on",
            "also localize each query frame on its own by Scan Context (whole-scan descriptors "
            "of the mapped scans, ICP from the match), the row scan-context"},
           {"out", Value::kText, "DIR", "", "output folder", kRequired}}),
      "",
      runEvalRevisits,
      /*stops_between_frames=*/true};
  return revisits;
}

}  // namespace semsegmap::app
