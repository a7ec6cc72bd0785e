// semsegmap eval semantics: how well the camera's classes land on the LiDAR points, against the
// dataset's per-point ground truth (SemanticKITTI's labels, the simulator's). The classes come
// from a label set (--labels) or the network of the config's semantics: section, never from the
// point labels. Built in every build: it needs no simulator.
#include <filesystem>
#include <iostream>

#include "cli_args.h"
#include "dataset_args.h"
#include "eval_args.h"
#include "interrupt.h"
#include "progress.h"
#include "semsegmap/core/json.h"
#include "semsegmap/eval/semantics_experiment.h"
#include "semsegmap/settings/config.h"

namespace semsegmap::app {

namespace {

int runEvalSemantics(const CliArgs& a) {
  const std::filesystem::path config = a.getPath("config"), out = a.get("out");
  SemanticsEvalConfig c;
  c.pipeline = loadPipelineConfig(config);
  c.max_frames = a.frameLimit();
  c.stop = stopToken();
  const std::unique_ptr<FrameSource> source = openDatasetArg(a, config);
  Progress progress("eval semantics", a.frameLimit(source->size()));
  const SemanticsEvaluation e =
      evaluateSemantics(*source, c, [&](size_t done, size_t) { progress.update(done); });
  const size_t total = a.frameLimit(source->size());
  // Stopped before its first frame: no scores of nothing (main removes what the run made).
  if (e.interrupted && e.frames.empty()) return interruptedRun("eval semantics", 0, total, "");
  std::filesystem::create_directories(out);
  writeJsonAtomically(out / "semantics.json", toJson(e));
  std::cout << semanticsTable(e) << "wrote " << (out / "semantics.json").string() << "\n";
  if (e.interrupted) return interruptedRun("eval semantics", e.frames.size(), total, out.string());
  return 0;
}

}  // namespace

const CommandSpec& evalSemanticsCommand() {
  static const CommandSpec semantics{
      "eval semantics",
      "camera classes on the LiDAR points against per-point ground truth -> semantics.json",
      datasetOptions(
          "a dataset with cameras and per-point ground-truth classes",
          {{"config", Value::kText, "FILE", "config/semsegmap.yaml",
            "voxel size, local map radius and segmentation; its semantics: section's network "
            "gives the camera classes unless --labels does (default: shipped)"},
           {"out", Value::kText, "DIR", "", "output folder", kRequired},
           maxFramesOption()}),
      "",
      runEvalSemantics,
      /*stops_between_frames=*/true};
  return semantics;
}

}  // namespace semsegmap::app
