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
#include "progress.h"
#include "semsegmap/io/atomic_file.h"
#include "semsegmap/io/config.h"
#include "semsegmap/learn/trainer.h"

namespace semsegmap::app {

namespace {

double parsePositive(const CliArgs& a, const std::string& name, double fallback) {
  if (!a.has(name)) return fallback;
  const std::string text = a.get(name, "");
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !(v > 0))
    throw std::invalid_argument("--" + name + " expects a positive number, got '" + text + "'");
  return v;
}

int positiveInt(const CliArgs& a, const std::string& name, int fallback) {
  const long long v = a.getInt(name, fallback);
  if (v < 1 || v > 1000000) throw std::invalid_argument("--" + name + " must be at least 1");
  return static_cast<int>(v);
}

std::string readText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// What the cached observations were made from: a different list, configuration or extraction
// setting means extracting again.
std::string provenance(const std::vector<std::string>& specs, const std::string& config_text,
                       const ExtractionConfig& e) {
  std::ostringstream s;
  s << "datasets:";
  for (const auto& spec : specs) s << ' ' << spec;
  s << "\nmin_purity: " << e.min_purity
    << "\nfirst_transient_instance: " << e.first_transient_instance
    << "\nmax_frames: " << e.max_frames
    << "\nmax_points_per_observation: " << e.max_points_per_observation << "\nseed: " << e.seed
    << "\nconfig:\n"
    << config_text;
  return s.str();
}

TrainingSet loadOrExtract(const std::vector<std::string>& specs, const PipelineConfig& pipeline,
                          const std::string& config_text, const ExtractionConfig& extraction,
                          const std::string& cache) {
  const std::string made_from = provenance(specs, config_text, extraction);
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
      specs, pipeline, extraction, [&](size_t done, size_t total, size_t dataset) {
        if (dataset != current) {
          current = dataset;
          progress = std::make_unique<Progress>("extract " + specs[dataset], total);
        }
        progress->update(done);
      });
  std::cout << "extracted " << set.observations.size() << " observations\n";
  if (!cache.empty()) {
    writeTrainingCache(cache, set, made_from);
    std::cout << "wrote " << cache << "\n";
  }
  return set;
}

// One line per epoch on stderr, redrawn as the steps go, with the time left for the whole run.
class EpochProgress {
 public:
  explicit EpochProgress(int epochs) : epochs_(epochs), start_(std::chrono::steady_clock::now()) {}

  void step(int epoch, size_t done, size_t total, double loss) {
    const double elapsed = seconds();
    if (done < total && elapsed - last_ < 0.5) return;
    last_ = elapsed;
    const double frac = (epoch - 1 + static_cast<double>(done) / total) / epochs_;
    const double left = frac > 0 ? elapsed * (1.0 - frac) / frac : 0.0;
    const int width = 20, filled = static_cast<int>(static_cast<double>(done) / total * width);
    std::fprintf(stderr, "\repoch %d/%d [%s%s] %zu/%zu  loss %.4f  %s  %.0f min left   ", epoch,
                 epochs_, std::string(filled, '#').c_str(),
                 std::string(width - filled, '.').c_str(), done, total, loss, validation_.c_str(),
                 left / 60.0);
    std::fflush(stderr);
  }
  void epoch(const EpochStats& s) {
    char text[96];
    std::snprintf(text, sizeof text, "val top1 %.3f top5 %.3f", s.validation.top1,
                  s.validation.top5);
    validation_ = text;
    std::fprintf(stderr, "\n");
    std::printf(
        "epoch %d  loss %.4f (triplet %.4f, reconstruction %.4f)  val top1 %.3f top5 %.3f "
        "(%zu queries)  %.0f s%s\n",
        s.epoch, s.loss, s.triplet_loss, s.reconstruction_loss, s.validation.top1,
        s.validation.top5, s.validation.queries, s.seconds, s.best ? "  best" : "");
    std::fflush(stdout);
  }

 private:
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  int epochs_;
  std::chrono::steady_clock::time_point start_;
  double last_ = -1.0;
  std::string validation_ = "val -";
};

// One row per epoch, for the model card.
void writeHistoryCsv(const std::filesystem::path& path, const std::vector<EpochStats>& history) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "epoch,loss,triplet_loss,reconstruction_loss,val_top1,val_top5,val_queries,"
           "learning_rate,seconds,best\n";
    for (const EpochStats& e : history)
      out << e.epoch << ',' << e.loss << ',' << e.triplet_loss << ',' << e.reconstruction_loss
          << ',' << e.validation.top1 << ',' << e.validation.top5 << ',' << e.validation.queries
          << ',' << e.learning_rate << ',' << e.seconds << ',' << (e.best ? 1 : 0) << '\n';
  });
}

}  // namespace

int runTrain(const std::vector<std::string>& args) {
  const CliArgs a(args,
                  {"descriptor", "dataset", "out", "epochs", "threads", "config", "batch",
                   "max-frames", "cache", "anchors-per-epoch", "lr", "seed", "points", "history"},
                  {});
  TrainConfig config = defaultTrainConfig(parseDescriptorKind(a.require("descriptor")));
  const std::vector<std::string> specs = splitDatasetSpecs(a.require("dataset"));
  const std::filesystem::path out = a.require("out");
  config.epochs = positiveInt(a, "epochs", config.epochs);
  config.threads = positiveInt(a, "threads", config.threads);
  config.batch_size = positiveInt(a, "batch", config.batch_size);
  config.learning_rate = parsePositive(a, "lr", config.learning_rate);
  config.net.num_points = positiveInt(a, "points", config.net.num_points);
  const long long anchors = a.getInt("anchors-per-epoch", 0);
  if (anchors < 0) throw std::invalid_argument("--anchors-per-epoch must not be negative");
  config.anchors_per_epoch = static_cast<size_t>(anchors);
  const long long seed = a.getInt("seed", 1);
  if (seed < 0) throw std::invalid_argument("--seed must not be negative");
  config.seed = static_cast<uint64_t>(seed);
  // Checked before the long extraction, not after it.
  if (config.net.kind != DescriptorKind::kSemSegMapNet &&
      config.net.kind != DescriptorKind::kSegMapCnn)
    throw std::invalid_argument("--descriptor " + a.require("descriptor") +
                                " is not learned (expected semsegmap-net or segmap-cnn)");
  validateNetConfig(config.net);

  ExtractionConfig extraction;
  const long long max_frames = a.getInt("max-frames", 0);
  if (max_frames < 0) throw std::invalid_argument("--max-frames must not be negative");
  extraction.max_frames = static_cast<size_t>(max_frames);
  // Without --config, the built-in defaults (those of config/semsegmap.yaml).
  PipelineConfig pipeline;
  std::string config_text = "(defaults)";
  if (a.has("config")) {
    pipeline = loadPipelineConfig(a.require("config"));
    config_text = readText(a.require("config"));
  }
  if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());

  const TrainingSet data =
      loadOrExtract(specs, pipeline, config_text, extraction, a.get("cache", ""));
  EpochProgress progress(config.epochs);
  TrainCallbacks callbacks;
  callbacks.step = [&](int epoch, size_t done, size_t total, double loss) {
    progress.step(epoch, done, total, loss);
  };
  callbacks.epoch = [&](const EpochStats& s) { progress.epoch(s); };
  const TrainResult result = trainDescriptor(data, config, out, callbacks);

  if (a.has("history")) {
    writeHistoryCsv(a.require("history"), result.history);
    std::cout << "wrote " << a.require("history") << "\n";
  }
  std::printf("trained on %zu observations (%zu anchors), validated on %zu\n",
              result.train_observations, result.anchors, result.validation_observations);
  const EpochStats& best = result.history.at(static_cast<size_t>(result.best_epoch - 1));
  std::printf("best epoch %d: val top1 %.3f top5 %.3f\n", best.epoch, best.validation.top1,
              best.validation.top5);
  std::cout << "wrote " << out.string() << " (" << descriptorName(config.net.kind)
            << ", fingerprint " << netFingerprint(*result.net) << ")\n";
  return 0;
}

}  // namespace semsegmap::app
