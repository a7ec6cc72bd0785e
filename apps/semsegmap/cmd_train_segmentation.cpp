// semsegmap train-segmentation: trains the project's camera segmentation network on a dataset's
// pictures and label images (the simulator's perfect ones) and writes it as ONNX, for the
// semantics: section of a config (learn/segmentation_trainer.h). Every N-th frame's pictures are
// kept, shrunk to the network's input size.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli_args.h"
#include "interrupt.h"
#include "progress.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/datasets/dataset_specs.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/learn/segmentation_trainer.h"

namespace semsegmap::app {

namespace {

// "WxH" -> width, height: multiples of 8 (the network's three stride-2 convolutions).
std::pair<int, int> inputSize(const CliArgs& a) {
  if (!a.has("input")) return {320, 240};
  const std::string text = a.get("input");
  int w = 0, h = 0;
  char x = 0, rest = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &rest) != 3 || x != 'x' || w < 8 || h < 8 ||
      w % 8 || h % 8 || w > 4096 || h > 4096)
    throw UsageError("--input: expected WxH, multiples of 8 up to 4096 (e.g. 320x240), got '" +
                     text + "'");
  return {w, h};
}

SegTrainConfig segmentationTrainConfig(const CliArgs& a) {
  SegTrainConfig c;
  std::tie(c.input_width, c.input_height) = inputSize(a);
  // The crop is 3/5 of the input each way, a multiple of 8 (192x144 of 320x240).
  c.crop_width = std::max(8, c.input_width * 3 / 5 / 8 * 8);
  c.crop_height = std::max(8, c.input_height * 3 / 5 / 8 * 8);
  if (a.has("epochs")) c.epochs = static_cast<int>(std::min<long long>(a.getInt("epochs"), 10000));
  if (a.has("threads")) c.threads = static_cast<int>(std::min<long long>(a.getInt("threads"), 256));
  if (a.has("seed")) c.seed = a.getCount("seed");
  return c;
}

// The frame's pictures with their label images, shrunk; a camera without either is an error.
void keepPictures(const Frame& frame, const std::string& spec, const SegTrainConfig& c,
                  std::vector<LabelledPicture>& pictures) {
  for (size_t k = 0; k < frame.cameras.size(); ++k) {
    const CameraFrame& cam = frame.cameras[k];
    if (cam.rgb.empty() || cam.label.empty())
      throw std::runtime_error(spec + ": frame " + std::to_string(frame.index) + " camera " +
                               std::to_string(k) + " has no " +
                               (cam.rgb.empty() ? "picture" : "label image") +
                               "; train-segmentation learns from pictures with label images");
    if (cam.rgb.width < c.input_width || cam.rgb.height < c.input_height)
      throw std::runtime_error(spec + ": frame " + std::to_string(frame.index) + " camera " +
                               std::to_string(k) + " is smaller than --input");
    pictures.push_back({shrinkPicture(cam.rgb, c.input_width, c.input_height),
                        shrinkLabels(cam.label, c.input_width, c.input_height)});
  }
}

// Returns false when stopped (Ctrl-C) while reading.
bool readPictures(const CliArgs& a, const SegTrainConfig& c,
                  std::vector<LabelledPicture>& pictures) {
  const size_t every = a.has("every") ? static_cast<size_t>(a.getInt("every")) : 10;
  for (const std::string& spec : splitDatasetSpecs(a.get("dataset"))) {
    const std::unique_ptr<FrameSource> source = openDataset(spec);
    if (source->info().rig.cameras.empty())
      throw std::runtime_error(spec + ": no cameras; train-segmentation learns from pictures");
    const size_t frames = a.frameLimit(source->size());
    Progress progress("read " + spec, (frames + every - 1) / every);
    for (size_t i = 0, n = 0; i < frames; i += every) {
      if (stopRequested()) return false;
      keepPictures(source->frame(i), spec, c, pictures);
      progress.update(++n);
    }
  }
  return true;
}

void writeHistory(const std::filesystem::path& path, const std::vector<SegEpochStats>& history) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "epoch,loss,train_accuracy,val_accuracy,val_miou,learning_rate,seconds\n";
    for (const SegEpochStats& e : history)
      out << e.epoch << ',' << e.loss << ',' << e.train_accuracy << ',' << e.val_accuracy << ','
          << e.val_miou << ',' << e.learning_rate << ',' << e.seconds << '\n';
  });
}

SegTrainCallbacks callbacks(const CliArgs& a, const SegTrainConfig& c,
                            std::vector<SegEpochStats>& history, ProgressLine& line) {
  SegTrainCallbacks cb;
  cb.stop = stopToken();
  const auto start = std::chrono::steady_clock::now();
  cb.step = [&line, start, epochs = c.epochs](int epoch, int step, int steps, double loss) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double in_epoch = static_cast<double>(step) / steps;
    if (step == 1) line = ProgressLine();
    if (!line.due(in_epoch, elapsed, step == steps)) return;
    const double frac = (epoch - 1 + in_epoch) / epochs;
    char text[160];
    std::snprintf(text, sizeof text, "epoch %d/%d %s %d/%d  loss %.4f  %.0f min left", epoch,
                  epochs, progressBar(in_epoch, 20).c_str(), step, steps, loss,
                  elapsed * (1.0 - frac) / frac / 60.0);
    line.write(text, step == steps);
  };
  cb.epoch = [&a, &history](const SegEpochStats& s) {
    history.push_back(s);
    if (a.has("history")) writeHistory(a.get("history"), history);
    std::printf("epoch %d  loss %.4f  train accuracy %.3f  val accuracy %.3f mIoU %.3f  %.0f s\n",
                s.epoch, s.loss, s.train_accuracy, s.val_accuracy, s.val_miou, s.seconds);
    std::fflush(stdout);
  };
  return cb;
}

int runTrainSegmentation(const CliArgs& a) {
  const SegTrainConfig config = segmentationTrainConfig(a);
  const std::filesystem::path out = a.get("out");
  const auto start = std::chrono::steady_clock::now();
  std::vector<LabelledPicture> pictures;
  if (!readPictures(a, config, pictures))
    return interruptedWork("train-segmentation", "while reading the pictures", "");
  std::printf("read %zu pictures (%dx%d) in %.0f s\n", pictures.size(), config.input_width,
              config.input_height,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  std::vector<SegEpochStats> history;
  ProgressLine line;
  const SegTrainResult r = trainSegmentation(pictures, config, callbacks(a, config, history, line));
  if (r.history.empty()) return interruptedWork("train-segmentation", "in the first epoch", "");
  writeBytesAtomically(out, r.onnx);
  std::printf("trained on %zu pictures, validated on %zu; %.0f s in all\n", r.train_pictures,
              r.validation_pictures,
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  if (a.has("history")) std::cout << "wrote " << a.get("history") << "\n";
  std::cout << "wrote " << out.string() << " (logits of " << kSegmentationClasses
            << " classes at half the input, class map semsegmap)\n";
  if (!r.interrupted) return 0;
  return interruptedWork("train-segmentation",
                         "after " + std::to_string(r.history.size()) + " of " +
                             std::to_string(config.epochs) + " epochs",
                         out.string() + " holds the model as it was then");
}

}  // namespace

const CommandSpec& trainSegmentationCommand() {
  static const CommandSpec command{
      "train-segmentation",
      "trains the camera segmentation network on pictures with label images -> ONNX",
      {
          {"dataset", Value::kText, "SPEC[,SPEC...]", "",
           "the runs to learn from: pictures with label images (the simulator's)", kRequired},
          {"out", Value::kText, "FILE.onnx", "", "the ONNX model to write", kRequired},
          {"epochs", Value::kPositive, "N", "16", "passes over the pictures"},
          {"threads", Value::kPositive, "N", "2", "torch threads"},
          {"input", Value::kText, "WxH", "320x240",
           "the network's input size (multiples of 8); pictures are shrunk to it, labels by "
           "nearest neighbour"},
          {"every", Value::kPositive, "N", "10", "keep every N-th frame's pictures"},
          maxFramesOption("read each run's first K frames only, 0: all"),
          {"seed", Value::kCount, "N", "1", "seed of weights, crops and augmentation"},
          {"history", Value::kText, "FILE.csv", "", "also write one row per epoch, after each"},
      },
      std::string("The model's output channel c is the project's class c: use it with class_map "
                  "semsegmap\n(config/semantics-sim-network.yaml). --dataset: a key=value after a "
                  "sim: spec belongs to it,\nany other item starts a new spec (';' also "
                  "separates).\n\n") +
          kDatasetNotes,
      runTrainSegmentation,
      /*stops_between_frames=*/true};
  return command;
}

}  // namespace semsegmap::app
