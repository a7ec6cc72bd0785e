// semsegmap label: the segmentation network of a config run once over a dataset's pictures; the
// label images are written as a label set (io/label_set.h) that later runs read with --labels,
// so the network's cost is paid once. Writes a preview of the first labelled picture.
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli_args.h"
#include "dataset_args.h"
#include "interrupt.h"
#include "progress.h"
#include "semsegmap/datasets/semantic_sources.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/io/label_set.h"
#include "semsegmap/settings/config.h"
#include "semsegmap/viz/label_overlay.h"

namespace semsegmap::app {

namespace {

// Writes every picture's labels of one frame; the first one is also the preview.
size_t writeFrameLabels(const Frame& frame, size_t index, const DatasetInfo& info,
                        const std::filesystem::path& out, bool& preview_written) {
  size_t written = 0;
  for (size_t k = 0; k < frame.cameras.size(); ++k) {
    const CameraFrame& camera = frame.cameras[k];
    if (camera.label.empty()) continue;
    writePng(labelSetImage(out, k, index), camera.label);
    ++written;
    if (preview_written) continue;
    const std::string title =
        info.name + ", frame " + std::to_string(index) + ", camera " + info.rig.cameras[k].name;
    writePng(out / "preview.png",
             viz::drawLabelOverlay(camera.rgb, camera.label, info.classes, title, 1600));
    preview_written = true;
  }
  return written;
}

int runLabel(const CliArgs& a) {
  const std::filesystem::path config = a.get("config"), out = a.get("out");
  const std::string model = loadSemanticsConfig(config).model;
  if (model.empty())
    throw std::runtime_error(config.string() +
                             ": semantics.model: empty; label runs the segmentation network "
                             "that this section names");
  auto source = openDatasetArg(a);  // loads the network and checks it on every camera
  const DatasetInfo& info = source->info();
  if (info.rig.cameras.empty())
    throw std::runtime_error("dataset '" + a.get("dataset") + "' has no cameras to label");
  for (size_t k = 0; k < info.rig.cameras.size(); ++k)
    std::filesystem::create_directories(labelSetImage(out, k, 0).parent_path());
  // labels.yaml says the set is whole: an earlier one goes first and the new one comes last, so
  // that a run stopped half way (an error, Ctrl-C) leaves a set that --labels refuses.
  std::filesystem::remove(out / "labels.yaml");

  const size_t n = a.frameLimit(source->size());
  size_t written = 0;
  bool preview = false;
  Progress progress("label", n);
  size_t done = 0;
  for (; done < n && !stopRequested(); ++done) {
    written += writeFrameLabels(source->frame(done), done, info, out, preview);
    progress.update(done + 1);
  }
  if (done == 0) return interruptedRun("label", 0, n, "");  // main removes the empty set
  // Stopped early (Ctrl-C), the set is kept and lists only the frames done: their pictures are
  // whole (written atomically, a frame at a time), the network's cost for them is paid, and
  // --labels refuses a run that reads beyond them (LabelSetInfo::frames). `interrupted` says
  // why it is short; removing the set would throw that work away for nothing.
  LabelSetInfo set;
  set.frames = done;  // the frames labelled, not the dataset's
  set.interrupted = done < n;
  set.dataset_frames = source->size();
  set.cameras = info.rig.cameras.size();
  set.dataset = a.get("dataset");
  set.model = model;
  writeLabelSetInfo(out, set);

  const LabelingStats s = labelerOf(*source)->stats();
  std::printf("frames %zu  label images %zu: network %zu (%.1f ms each), reused %zu, kept %zu\n",
              done, written, s.network_runs, s.network_runs ? s.network_ms / s.network_runs : 0.0,
              s.reused, s.kept);
  std::cout << "wrote " << out.string() << " (labels.yaml, cam*/, preview.png); read it with "
            << "--labels " << out.string() << "\n";
  if (set.interrupted) return interruptedRun("label", done, n, out.string());
  return 0;
}

}  // namespace

const CommandSpec& labelCommand() {
  static const CommandSpec command{
      "label",
      "the config's segmentation network over a dataset's pictures -> a label set (--labels DIR)",
      datasetOptions("the dataset",
                     {
                         {"config", Value::kText, "FILE", "",
                          "configuration whose semantics: section names the network", kRequired},
                         {"out", Value::kText, "DIR", "", "the label set's folder", kRequired},
                         maxFramesOption(),
                     },
                     false),
      kDatasetNotes,
      runLabel,
      /*stops_between_frames=*/true};
  return command;
}

}  // namespace semsegmap::app
