// semsegmap train: extracts segment observations with their ground-truth instances from
// simulated runs (or reads them from --cache) and trains a learned descriptor on them; the model
// of the best epoch (validation retrieval top-1) is written to --out.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "cli_args.h"
#include "eval_args.h"
#include "interrupt.h"
#include "progress.h"
#include "resources.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/artefacts/training_cache.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/binary_io.h"
#include "semsegmap/datasets/dataset_specs.h"
#include "semsegmap/learn/smoothnet_trainer.h"
#include "semsegmap/learn/trainer.h"
#include "semsegmap/settings/config.h"

namespace semsegmap::app {

namespace {

// A kPositive option, bounded (`fallback`, the library's default, when it is not given).
int positiveInt(const CliArgs& a, const std::string& name, int fallback) {
  if (!a.has(name)) return fallback;
  const long long v = a.getInt(name);
  if (v > 1000000)
    throw UsageError("option --" + name + " must be at most 1000000, got '" + a.get(name) + "'");
  return static_cast<int>(v);
}

// What the cached observations were made from: a different list, configuration or extraction
// setting means extracting again.
std::string provenance(const std::vector<std::string>& specs, const std::string& config_text,
                       const ExtractionConfig& e, const SemanticsConfig& network) {
  std::ostringstream s;
  s << "datasets:";
  for (const auto& spec : specs) s << ' ' << spec;
  s << "\nmin_purity: " << e.min_purity << "\nmax_frames: " << e.max_frames
    << "\nmax_points_per_observation: " << e.max_points_per_observation << "\nseed: " << e.seed
    << "\nconfig:\n"
    << config_text;
  // A network retrained under the same file name labels otherwise: its bytes count too.
  if (!network.model.empty()) {
    const std::string model = readFileBytes(network.model);
    s << "\nnetwork: " << std::hex << fnv1a64(model.data(), model.size()) << std::dec << " rate_hz "
      << network.rate_hz << " budget_cores " << network.budget_cores << " latency_s "
      << network.latency_s << " tolerance_s " << network.tolerance_s;
  }
  return s.str();
}

TrainingSet loadOrExtract(const std::vector<std::string>& specs, const PipelineConfig& pipeline,
                          const std::string& config_text, const ExtractionConfig& extraction,
                          const DatasetOptions& options, const std::string& cache) {
  const std::string made_from = provenance(specs, config_text, extraction, options.semantics);
  if (!cache.empty()) {
    if (auto set = readTrainingCache(cache, made_from)) {
      std::cout << "read " << set->observations.size() << " observations from " << cache << "\n";
      return std::move(*set);
    }
    if (std::filesystem::exists(cache))
      std::cout << cache << " was made from other data or settings: extracting again\n";
  }
  std::unique_ptr<Progress> progress;
  size_t current = specs.size();
  TrainingSet set = extractTrainingSet(
      specs, pipeline, extraction,
      [&](size_t done, size_t total, size_t dataset) {
        if (dataset != current) {
          current = dataset;
          progress = std::make_unique<Progress>("extract " + specs[dataset], total);
        }
        progress->update(done);
      },
      options);
  if (set.interrupted) return set;  // a part of the data, never cached as the whole
  std::cout << "extracted " << set.observations.size() << " observations\n";
  if (!cache.empty()) {
    writeTrainingCache(cache, set, made_from);
    std::cout << "wrote " << cache << "\n";
  }
  return set;
}

// One line per epoch on stderr as the steps go, with the time left for the whole run (redrawn
// on a terminal, a line every tenth of an epoch or 30 s into a log).
class EpochProgress {
 public:
  // `keypoints`: 3dsmoothnet's epochs, whose loss is over keypoint pairs and whose validation
  // ranks keypoints, not segments.
  EpochProgress(int epochs, bool distilled, bool keypoints = false)
      : epochs_(epochs),
        distilled_(distilled),
        keypoints_(keypoints),
        start_(std::chrono::steady_clock::now()) {}

  void step(int epoch, size_t done, size_t total, double loss) {
    if (epoch != epoch_) {
      epoch_ = epoch;
      line_ = ProgressLine();
    }
    const double elapsed = seconds();
    const double in_epoch = total ? static_cast<double>(done) / total : 1.0;
    if (!line_.due(in_epoch, elapsed, done >= total)) return;
    const double frac = (epoch - 1 + in_epoch) / epochs_;
    const double left = frac > 0 ? elapsed * (1.0 - frac) / frac : 0.0;
    char text[160];
    std::snprintf(text, sizeof text, "epoch %d/%d %s %zu/%zu  loss %.4f  %s  %.0f min left", epoch,
                  epochs_, progressBar(in_epoch, 20).c_str(), done, total, loss,
                  validation_.c_str(), left / 60.0);
    line_.write(text, done >= total);
  }
  void epoch(const EpochStats& s) {
    char text[96];
    std::snprintf(text, sizeof text, "val top1 %.3f top5 %.3f", s.validation.top1,
                  s.validation.top5);
    validation_ = text;
    if (keypoints_) {
      std::printf(
          "epoch %d  loss %.4f  keypoints' counterparts top1 %.3f top5 %.3f (%zu pairs)"
          "  %.0f s%s\n",
          s.epoch, s.loss, s.validation.top1, s.validation.top5, s.validation.queries, s.seconds,
          s.best ? "  best" : "");
      std::fflush(stdout);
      return;
    }
    char distillation[48] = "";
    if (distilled_)
      std::snprintf(distillation, sizeof distillation, ", distillation %.4f", s.distillation_loss);
    std::printf(
        "epoch %d  loss %.4f (triplet %.4f, reconstruction %.4f%s)  val top1 %.3f top5 %.3f "
        "(%zu queries)  %.0f s%s\n",
        s.epoch, s.loss, s.triplet_loss, s.reconstruction_loss, distillation, s.validation.top1,
        s.validation.top5, s.validation.queries, s.seconds, s.best ? "  best" : "");
    std::fflush(stdout);
  }

 private:
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  int epochs_;
  bool distilled_;
  bool keypoints_;
  std::chrono::steady_clock::time_point start_;
  int epoch_ = 0;
  ProgressLine line_;
  std::string validation_ = "val -";
};

// One row per epoch, for the model card.
void writeHistoryCsv(const std::filesystem::path& path, const std::vector<EpochStats>& history) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "epoch,loss,triplet_loss,reconstruction_loss,distillation_loss,val_top1,val_top5,"
           "val_queries,learning_rate,seconds,best\n";
    for (const EpochStats& e : history)
      out << e.epoch << ',' << e.loss << ',' << e.triplet_loss << ',' << e.reconstruction_loss
          << ',' << e.distillation_loss << ',' << e.validation.top1 << ',' << e.validation.top5
          << ',' << e.validation.queries << ',' << e.learning_rate << ',' << e.seconds << ','
          << (e.best ? 1 : 0) << '\n';
  });
}

double probability(const CliArgs& a, const std::string& option) {
  const double p = a.getNumber(option);
  if (!(p >= 0 && p <= 1))
    throw std::invalid_argument("--" + option + ": " + a.get(option) +
                                " is not a probability in [0, 1]");
  return p;
}

// The training settings from the options; what is not given keeps the library's default for
// the descriptor (defaultTrainConfig).
TrainConfig trainConfig(const CliArgs& a) {
  TrainConfig config = defaultTrainConfig(parseDescriptorKind(a.get("descriptor")));
  config.epochs = positiveInt(a, "epochs", config.epochs);
  config.threads = positiveInt(a, "threads", config.threads);
  config.batch_size = positiveInt(a, "batch", config.batch_size);
  config.net.num_points = positiveInt(a, "points", config.net.num_points);
  if (a.has("lr")) config.learning_rate = a.getNumber("lr");
  if (a.has("anchors-per-epoch")) config.anchors_per_epoch = a.getCount("anchors-per-epoch");
  if (a.has("seed")) config.seed = a.getCount("seed");
  if (a.has("confused-sections"))
    config.augmentation.confused_section_probability = probability(a, "confused-sections");
  if (a.has("modality-dropout"))
    config.augmentation.modality_dropout_probability = probability(a, "modality-dropout");
  if (a.has("partial-coverage"))
    config.augmentation.partial_coverage_probability = probability(a, "partial-coverage");
  for (const char* option : {"lidar-only", "modality-dropout", "partial-coverage"})
    if (a.has(option) && config.net.kind != DescriptorKind::kSemSegMapNet)
      throw UsageError(std::string("--") + option + ": only semsegmap-net sees colour and classes");
  for (const char* option : {"modality-dropout", "partial-coverage"})
    if (a.has("lidar-only") && a.has(option))
      throw UsageError(std::string("--") + option +
                       ": a --lidar-only network sees neither modality anyway");
  if (a.has("lidar-only")) config.net.use_color = config.net.use_classes = false;
  for (const char* option : {"distillation-weight", "from-scratch"})
    if (a.has(option) && !a.has("teacher"))
      throw UsageError(std::string("--") + option + ": only with --teacher");
  // The teacher would see what the dropout took from the student, and teach it nothing.
  for (const char* option : {"modality-dropout", "partial-coverage"})
    if (a.has("teacher") && a.has(option))
      throw UsageError(std::string("--") + option +
                       ": the teacher would see the same dropped observation");
  if (a.has("distillation-weight")) {
    config.distillation_weight = a.getNumber("distillation-weight");
    if (!(config.distillation_weight >= 0 && config.distillation_weight <= 1e6))
      throw UsageError("--distillation-weight: " + a.get("distillation-weight") +
                       " is not in [0, 1e6]");
  }
  config.start_from_teacher = !a.has("from-scratch");
  validateNetConfig(config.net);  // before the long extraction, not after it
  return config;
}

// The teacher, read and checked against the student before the long extraction.
std::shared_ptr<DescriptorNetImpl> loadTeacher(const CliArgs& a, const TrainConfig& config) {
  if (!a.has("teacher")) return nullptr;
  auto teacher = loadNet(a.get("teacher"), config.net.kind);
  try {
    checkTeacher(config, *teacher);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(a.get("teacher") + ": " + e.what());
  }
  std::cout << "distilling from " << a.get("teacher") << " (fingerprint "
            << netFingerprint(*teacher) << ", weight " << config.distillation_weight
            << "), starting from " << (config.start_from_teacher ? "its weights" : "fresh weights")
            << "\n";
  return teacher;
}

// What a training run ends with: the best epoch and the model written. Ctrl-C keeps the model of
// the best epoch completed, which the run saved when that epoch ended, and the history of the
// epochs completed; stopped in the first epoch, it has written nothing.
int trainEnd(const CliArgs& a, const TrainConfig& config, const TrainResult& result) {
  const size_t epochs = result.history.size();
  const std::string where =
      "after " + std::to_string(epochs) + " of " + std::to_string(config.epochs) + " epochs";
  if (epochs == 0) return interruptedWork("train", where, "");
  if (a.has("history")) std::cout << "wrote " << a.get("history") << "\n";
  std::printf("trained on %zu observations (%zu anchors), validated on %zu\n",
              result.train_observations, result.anchors, result.validation_observations);
  const EpochStats& best = result.history.at(static_cast<size_t>(result.best_epoch - 1));
  std::printf("best epoch %d: val top1 %.3f top5 %.3f\n", best.epoch, best.validation.top1,
              best.validation.top5);
  std::cout << "wrote " << a.get("out") << " (" << descriptorName(config.net.kind)
            << ", fingerprint " << netFingerprint(*result.net) << ")\n";
  if (!result.interrupted) return 0;
  return interruptedWork("train", where,
                         a.get("out") + " holds the model of epoch " + std::to_string(best.epoch) +
                             ", the best of the " + std::to_string(epochs) + " epochs done");
}

// The observations of --dataset (or --cache), with the pipeline of --config and the camera
// labels of --labels.
TrainingSet trainingData(const CliArgs& a) {
  const std::vector<std::string> specs = splitDatasetSpecs(a.get("dataset"));
  ExtractionConfig extraction;
  extraction.max_frames = a.frameLimit();
  // Without --config, the built-in defaults (those of config/semsegmap.yaml).
  PipelineConfig pipeline;
  std::string config_text = "(defaults)";
  DatasetOptions options;
  if (a.has("config")) {
    pipeline = loadPipelineConfig(a.get("config"));
    config_text = readFileBytes(a.get("config"));
  }
  // --labels network: the segmentation network's labels replace the simulator's perfect ones,
  // within its budget, as in `eval localization --labels`: the descriptor learns the classes it
  // will be given, errors included.
  const LabelPass labels = labelPass(a.get("labels"));
  if (!labels.network.model.empty()) {
    options.semantics = labels.network;
    options.semantics.replace_dataset_labels = true;  // the simulator's are perfect
    options.class_maps_dir = shippedFile("config/class_maps");
    if (labels.geometric_ground_removal) pipeline.local_map.geometric_ground_removal = true;
    config_text += "\nlabels: " + labels.labels;
    std::cout << "the runs' pictures labelled by " << labels.network.model
              << " instead of the simulator's perfect labels\n";
  }
  extraction.stop = stopToken();
  return loadOrExtract(specs, pipeline, config_text, extraction, options,
                       a.has("cache") ? a.get("cache") : "");
}

// Ctrl-C, the progress line, and the history so far written to its file after every epoch,
// before the epoch is printed: a run stopped early (a day's budget, a killed job) keeps both its
// best model and its history.
TrainCallbacks epochCallbacks(const CliArgs& a, EpochProgress& progress,
                              std::vector<EpochStats>& history) {
  TrainCallbacks callbacks;
  callbacks.stop = stopToken();
  callbacks.step = [&progress](int epoch, size_t done, size_t total, double loss) {
    progress.step(epoch, done, total, loss);
  };
  callbacks.epoch = [&a, &progress, &history](const EpochStats& s) {
    history.push_back(s);
    if (a.has("history")) writeHistoryCsv(a.get("history"), history);
    progress.epoch(s);
  };
  return callbacks;
}

// The options of the segment descriptors' training that 3dsmoothnet has no use for.
constexpr const char* kNotForSmoothNet[] = {
    "anchors-per-epoch",   "confused-sections", "modality-dropout",
    "partial-coverage",    "lidar-only",        "teacher",
    "distillation-weight", "from-scratch",      "points"};
// ... and those only it has.
constexpr const char* kOnlyForSmoothNet[] = {"words", "keypoints", "steps"};

SmoothNetTrainConfig smoothNetTrainConfig(const CliArgs& a) {
  for (const char* option : kNotForSmoothNet)
    if (a.has(option))
      throw UsageError(std::string("--") + option + ": not an option of 3dsmoothnet's training");
  SmoothNetTrainConfig config = defaultSmoothNetTrainConfig();
  config.epochs = positiveInt(a, "epochs", config.epochs);
  config.threads = positiveInt(a, "threads", config.threads);
  config.batch_pairs = positiveInt(a, "batch", config.batch_pairs);
  config.steps_per_epoch =
      static_cast<size_t>(positiveInt(a, "steps", static_cast<int>(config.steps_per_epoch)));
  config.net.descriptor_dim = positiveInt(a, "words", config.net.descriptor_dim);
  config.net.smoothnet_keypoints = positiveInt(a, "keypoints", config.net.smoothnet_keypoints);
  if (a.has("lr")) config.learning_rate = a.getNumber("lr");
  if (a.has("seed")) config.seed = a.getCount("seed");
  validateNetConfig(config.net);  // before the long extraction, not after it
  return config;
}

// 3dsmoothnet: keypoint pairs and then the visual words (learn/smoothnet_trainer.h); the model
// is written once, when its words are fitted.
int runTrainSmoothNet(const CliArgs& a) {
  const SmoothNetTrainConfig config = smoothNetTrainConfig(a);
  const TrainingSet data = trainingData(a);
  if (data.interrupted) return interruptedWork("train", "while extracting the training data", "");
  EpochProgress progress(config.epochs, false, true);
  std::vector<EpochStats> history;
  const TrainCallbacks callbacks = epochCallbacks(a, progress, history);
  const SmoothNetTrainResult result = trainSmoothNet(data, config, callbacks);
  const TrainResult& training = result.training;
  if (training.net == nullptr) return interruptedWork("train", "in the first epoch", "");
  saveNet(a.get("out"), *training.net);
  std::printf("fitted %d visual words to %zu keypoint descriptors in %.0f s\n",
              config.net.descriptor_dim, result.word_keypoints, result.word_seconds);
  std::printf("segment retrieval on the validation objects: top1 %.3f top5 %.3f (%zu queries)\n",
              result.segments.top1, result.segments.top5, result.segments.queries);
  TrainConfig shown;
  shown.net = config.net;
  shown.epochs = config.epochs;
  return trainEnd(a, shown, training);
}

int runTrain(const CliArgs& a) {
  if (parseDescriptorKind(a.get("descriptor")) == DescriptorKind::kSmoothNetBow)
    return runTrainSmoothNet(a);
  for (const char* option : kOnlyForSmoothNet)
    if (a.has(option)) throw UsageError(std::string("--") + option + ": only for 3dsmoothnet");
  const TrainConfig config = trainConfig(a);
  const auto teacher = loadTeacher(a, config);
  const std::filesystem::path out = a.get("out");
  const TrainingSet data = trainingData(a);
  if (data.interrupted) return interruptedWork("train", "while extracting the training data", "");
  EpochProgress progress(config.epochs, teacher != nullptr);
  std::vector<EpochStats> history;
  TrainCallbacks callbacks = epochCallbacks(a, progress, history);
  callbacks.best = [&](DescriptorNetImpl& net) { saveNet(out, net); };
  const TrainResult result = trainDescriptor(data, config, callbacks, teacher);
  return trainEnd(a, config, result);
}

}  // namespace

const CommandSpec& trainCommand() {
  const TrainConfig net = defaultTrainConfig(DescriptorKind::kSemSegMapNet);
  const TrainConfig cnn = defaultTrainConfig(DescriptorKind::kSegMapCnn);
  const SmoothNetTrainConfig smooth = defaultSmoothNetTrainConfig();
  // The library's defaults as the help shows them: one value, or one per descriptor.
  auto shown = [&](auto field) {
    std::ostringstream s;
    s << "(default: " << field(net);
    if (field(cnn) != field(net)) s << "; " << field(cnn) << " for segmap-cnn";
    s << ")";
    return s.str();
  };
  // ... and with 3dsmoothnet's, for the options its training shares.
  auto shownAll = [&](auto field, auto smooth_value) {
    std::string text = shown(field);
    std::ostringstream s;
    s << "; " << smooth_value << " for 3dsmoothnet)";
    return text.substr(0, text.size() - 1) + s.str();
  };
  static const CommandSpec command{
      "train",
      "trains a learned descriptor on simulated ground truth; its best epoch -> --out",
      {
          {"descriptor", Value::kText, "semsegmap-net|segmap-cnn|3dsmoothnet", "",
           "the descriptor to train", kRequired},
          {"dataset", Value::kText, "SPEC[,SPEC...]", "", "the runs to learn from", kRequired},
          {"out", Value::kText, "FILE", "", "the model file to write", kRequired},
          {"epochs", Value::kPositive, "N", "",
           "epochs " + shownAll([](const TrainConfig& c) { return c.epochs; }, smooth.epochs)},
          {"batch", Value::kPositive, "N", "",
           "triplets a step (3dsmoothnet: keypoint pairs) " +
               shownAll([](const TrainConfig& c) { return c.batch_size; }, smooth.batch_pairs)},
          {"threads", Value::kPositive, "N", "",
           "torch threads " +
               shownAll([](const TrainConfig& c) { return c.threads; }, smooth.threads)},
          {"config", Value::kText, "FILE", "",
           "pipeline configuration that cuts the runs into segments (default: built-in, as "
           "config/semsegmap.yaml)"},
          maxFramesOption("stop each run after its first K frames, 0: all"),
          {"labels", Value::kText, "SPEC", "perfect",
           "camera labels of the runs: perfect (the simulator's) or network[,KEY=V...], a "
           "segmentation network's as eval localization --labels reads it (network: the shipped "
           "one, config/semantics-sim-network.yaml, at its budget)"},
          {"cache", Value::kText, "FILE", "",
           "read the observations from FILE if made from the same data and settings, else "
           "extract and write them there"},
          {"anchors-per-epoch", Value::kCount, "N", "",
           "anchors drawn per epoch, 0: every observation with a positive " +
               shown([](const TrainConfig& c) { return c.anchors_per_epoch; })},
          {"lr", Value::kNumber, "X", "",
           "Adam's learning rate " + shownAll([](const TrainConfig& c) { return c.learning_rate; },
                                              smooth.learning_rate)},
          {"seed", Value::kCount, "N", "",
           "seed of weights, sampling and augmentation " +
               shown([](const TrainConfig& c) { return c.seed; })},
          {"confused-sections", Value::kNumber, "P", "",
           "probability that a training observation gets a planar section of up to half its "
           "points relabelled as a segmentation network confuses them (fence/building/"
           "vegetation, terrain/sidewalk, missed poles) " +
               shown([](const TrainConfig& c) {
                 return c.augmentation.confused_section_probability;
               })},
          {"modality-dropout", Value::kNumber, "P", "",
           "probability, drawn separately for colour and for classes, that a training "
           "observation loses all of it, so that the model also serves a LiDAR without a camera "
           "or a segmentation network " +
               shown([](const TrainConfig& c) {
                 return c.augmentation.modality_dropout_probability;
               })},
          {"partial-coverage", Value::kNumber, "P", "",
           "probability that a training observation loses colour and classes beyond a vertical "
           "plane (up to 90 % of its points), as a segment at the edge of a camera's picture "
           "does on a LiDAR the cameras cover only in part " +
               shown([](const TrainConfig& c) {
                 return c.augmentation.partial_coverage_probability;
               })},
          {"lidar-only", Value::kFlag, "", "",
           "the network sees geometry only (no colour, no classes): the model for a LiDAR "
           "without a camera (descriptor.model_lidar_only)"},
          {"teacher", Value::kText, "FILE", "",
           "distil a trained model of the same descriptor: the student is also pulled towards "
           "its descriptor of each observation, which it sees with colour and classes (with "
           "--lidar-only, the student learns from geometry what the teacher knows with them)"},
          {"distillation-weight", Value::kWeight, "X", "",
           "weight of the distillation's mean squared descriptor distance against the triplet "
           "loss; 0: the teacher only gives the starting weights " +
               shown([](const TrainConfig& c) { return c.distillation_weight; })},
          {"from-scratch", Value::kFlag, "", "",
           "with --teacher, start from fresh weights instead of the teacher's"},
          {"points", Value::kPositive, "N", "",
           "points a segment is subsampled to " +
               shown([](const TrainConfig& c) { return c.net.num_points; })},
          {"history", Value::kText, "FILE.csv", "", "also write one row per epoch, after each"},
          {"words", Value::kPositive, "K", "",
           "3dsmoothnet: visual words of the bag, k-means centres of keypoint descriptors "
           "(default: " +
               std::to_string(smooth.net.descriptor_dim) + ", the paper's best)"},
          {"keypoints", Value::kPositive, "N", "",
           "3dsmoothnet: random keypoints a segment is described at (default: " +
               std::to_string(smooth.net.smoothnet_keypoints) + ")"},
          {"steps", Value::kPositive, "N", "",
           "3dsmoothnet: steps an epoch (default: " + std::to_string(smooth.steps_per_epoch) + ")"},
      },
      std::string("--dataset: a key=value after a sim: spec belongs to it, any other item starts a "
                  "new spec\n(';' also separates): sim:world=1,run=S1,sim:world=1,run=S1,"
                  "condition=sunrise\n\n") +
          kDatasetNotes,
      runTrain,
      /*stops_between_frames=*/true};
  return command;
}

}  // namespace semsegmap::app
