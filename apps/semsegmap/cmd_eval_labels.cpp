// semsegmap eval labels: the config's segmentation network against a dataset's own label images
// (the simulator's), pixel by pixel at the cameras' resolution -> labels.json (per-class IoU,
// mean IoU, pixel accuracy, time per picture) and labels.png (picture | truth | network). Built
// in every build: it needs no simulator or libtorch.
#include <filesystem>
#include <iostream>

#include "cli_args.h"
#include "eval_args.h"
#include "interrupt.h"
#include "progress.h"
#include "resources.h"
#include "semsegmap/core/json.h"
#include "semsegmap/datasets/dataset_specs.h"
#include "semsegmap/eval/label_eval.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/settings/config.h"
#include "semsegmap/viz/label_comparison.h"

namespace semsegmap::app {

namespace {

int runEvalLabels(const CliArgs& a) {
  const std::filesystem::path config = a.get("config"), out = a.get("out");
  LabelEvalConfig c;
  c.semantics = loadSemanticsConfig(config);
  if (c.semantics.model.empty())
    throw std::runtime_error(config.string() +
                             ": semantics.model: no network to evaluate (the section names none)");
  c.class_maps_dir = shippedFile("config/class_maps");
  c.every = a.has("every") ? static_cast<size_t>(a.getInt("every")) : 1;
  c.max_frames = a.frameLimit();
  c.stop = stopToken();
  std::unique_ptr<Progress> progress;
  std::string current;
  const LabelEvaluation e =
      evaluateLabels(splitDatasetSpecs(a.get("dataset")), c,
                     [&](const std::string& spec, size_t done, size_t total) {
                       if (spec != current)
                         progress = std::make_unique<Progress>("eval labels " + spec, total);
                       current = spec;
                       progress->update(done);
                     });
  if (e.pictures == 0) return interruptedWork("eval labels", "before its first picture", "");
  std::filesystem::create_directories(out);
  writeJsonAtomically(out / "labels.json", toJson(e));
  if (!e.examples.empty())
    writePng(out / "labels.png", viz::drawLabelComparisons(e.examples, e.classes));
  std::cout << labelsTable(e) << "wrote " << (out / "labels.json").string() << " and "
            << (out / "labels.png").string() << "\n";
  if (e.interrupted)
    return interruptedWork("eval labels", "after " + std::to_string(e.pictures) + " pictures",
                           out.string() + " holds the scores of those");
  return 0;
}

}  // namespace

const CommandSpec& evalLabelsCommand() {
  static const CommandSpec labels{
      "eval labels",
      "the config's segmentation network against a dataset's label images -> labels.json, .png",
      {
          {"dataset", Value::kText, "SPEC[,SPEC...]", "",
           "datasets with pictures and label images (the simulator's)", kRequired},
          {"config", Value::kText, "FILE", "",
           "a config whose semantics: section names the network (e.g. "
           "config/semantics-sim-network.yaml)",
           kRequired},
          {"out", Value::kText, "DIR", "", "output folder", kRequired},
          {"every", Value::kPositive, "N", "1", "label every N-th frame's pictures"},
          maxFramesOption("read each dataset's first K frames only, 0: all"),
      },
      std::string("Scores are at the cameras' resolution. mIoU is over every class with "
                  "ground-truth pixels\nbut unknown, sky included; mIoU without sky is reported "
                  "too.\n\n") +
          kDatasetNotes,
      runEvalLabels,
      /*stops_between_frames=*/true};
  return labels;
}

}  // namespace semsegmap::app
