// semsegmap eval <experiment>: the paper's experiments as commands (eval/*_experiment.h), each
// printing its table and writing JSON and pictures; `eval paper` runs all three and writes
// report.md.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "cli_args.h"
#include "progress.h"
#include "semsegmap/eval/report.h"
#include "semsegmap/io/atomic_file.h"

namespace semsegmap::app {

namespace {

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

size_t maxFrames(const CliArgs& a) {
  const long long n = a.getInt("max-frames", 0);
  if (n < 0) throw std::invalid_argument("--max-frames must not be negative");
  return static_cast<size_t>(n);
}

// The configurations compared: SemSegMap first, the SegMap baseline second.
std::vector<NamedConfig> comparedConfigs(const CliArgs& a) {
  std::vector<NamedConfig> configs;
  for (const std::string& path :
       splitList(a.get("configs", "config/semsegmap.yaml,config/segmap.yaml")))
    configs.push_back(loadNamedConfig(path));
  return configs;
}

const std::set<std::string> kCommon = {"world-seed", "out", "preset", "max-frames"};
std::set<std::string> optionsWith(std::set<std::string> extra) {
  extra.insert(kCommon.begin(), kCommon.end());
  return extra;
}

SegmentationExperimentConfig segmentationConfig(const CliArgs& a) {
  SegmentationExperimentConfig c;
  c.world_seed = static_cast<uint64_t>(a.getInt("world-seed", 1));
  c.preset = a.get("preset", "full");
  c.run = a.get("segmentation-run", "S1");
  c.max_frames = maxFrames(a);
  c.configs = comparedConfigs(a);
  return c;
}

DescriptorExperimentConfig descriptorConfig(const CliArgs& a) {
  DescriptorExperimentConfig c;
  c.world_seed = static_cast<uint64_t>(a.getInt("world-seed", 1));
  c.preset = a.get("preset", "full");
  c.run = a.get("descriptor-run", "S0");
  c.max_frames = maxFrames(a);
  c.segmentation = loadNamedConfig(a.get("config", "config/semsegmap.yaml"));
  c.models = a.get("models", "models");
  c.descriptors = splitList(a.get("descriptors", "semsegmap-net,segmap-cnn,fpfh,eigen"));
  c.threads = static_cast<int>(a.getInt("threads", 0));
  return c;
}

LocalizationExperimentConfig localizationConfig(const CliArgs& a) {
  LocalizationExperimentConfig c;
  c.world_seed = static_cast<uint64_t>(a.getInt("world-seed", 1));
  c.preset = a.get("preset", "full");
  c.map_run = a.get("map-run", "S0");
  c.query_runs = splitList(a.get("query-runs", "S2,S3"));
  c.max_frames = maxFrames(a);
  c.configs = comparedConfigs(a);
  return c;
}

int runEvalSegmentation(const std::vector<std::string>& args) {
  const CliArgs a(args, optionsWith({"configs", "segmentation-run"}), {});
  StageProgress progress;
  const SegmentationExperiment e =
      runSegmentationExperiment(segmentationConfig(a), a.require("out"), std::ref(progress));
  std::cout << segmentationTable(e) << "wrote "
            << (std::filesystem::path(a.require("out")) / "segmentation.json").string()
            << ", segmentation.png\n";
  return 0;
}

int runEvalDescriptors(const std::vector<std::string>& args) {
  const CliArgs a(
      args, optionsWith({"config", "models", "descriptors", "threads", "descriptor-run"}), {});
  StageProgress progress;
  const DescriptorExperiment e =
      runDescriptorExperiment(descriptorConfig(a), a.require("out"), std::ref(progress));
  std::cout << descriptorTable(e) << "wrote "
            << (std::filesystem::path(a.require("out")) / "descriptors.json").string()
            << ", descriptors.png\n";
  return 0;
}

int runEvalLocalization(const std::vector<std::string>& args) {
  const CliArgs a(args, optionsWith({"configs", "map-run", "query-runs"}), {});
  StageProgress progress;
  const LocalizationExperiment e =
      runLocalizationExperiment(localizationConfig(a), a.require("out"), std::ref(progress));
  std::cout << localizationTable(e) << "wrote "
            << (std::filesystem::path(a.require("out")) / "localization.json").string()
            << ", localization_accuracy.png and one folder per run\n";
  return 0;
}

int runEvalPaper(const std::vector<std::string>& args) {
  const CliArgs a(args,
                  optionsWith({"configs", "config", "models", "descriptors", "threads",
                               "segmentation-run", "descriptor-run", "map-run", "query-runs"}),
                  {});
  const std::filesystem::path out = a.require("out");
  const auto start = std::chrono::steady_clock::now();
  // Every configuration and model is read before the first experiment starts.
  const SegmentationExperimentConfig sc = segmentationConfig(a);
  const DescriptorExperimentConfig dc = descriptorConfig(a);
  const LocalizationExperimentConfig lc = localizationConfig(a);
  StageProgress progress;
  const SegmentationExperiment s = runSegmentationExperiment(sc, out, std::ref(progress));
  std::cout << segmentationTable(s) << "\n";
  const DescriptorExperiment d = runDescriptorExperiment(dc, out, std::ref(progress));
  std::cout << descriptorTable(d) << "\n";
  const LocalizationExperiment l = runLocalizationExperiment(lc, out, std::ref(progress));
  std::cout << localizationTable(l) << "\n";
  ReportContext context;
  context.title = "SemSegMap against SegMap: the paper's experiments on world " +
                  std::to_string(sc.world_seed) + " (" + sc.preset + ")";
  context.command = "semsegmap eval paper";
  for (const std::string& arg : args) context.command += " " + arg;
  context.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  writeBytesAtomically(out / "report.md", paperReport(context, &s, &d, &l));
  std::cout << "wrote " << (out / "report.md").string() << "\n";
  return 0;
}

}  // namespace

int runEval(const std::vector<std::string>& args) {
  const std::string expected = "segmentation, descriptors, localization or paper";
  if (args.empty()) throw std::invalid_argument("eval needs an experiment: " + expected);
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (args[0] == "segmentation") return runEvalSegmentation(rest);
  if (args[0] == "descriptors") return runEvalDescriptors(rest);
  if (args[0] == "localization") return runEvalLocalization(rest);
  if (args[0] == "paper") return runEvalPaper(rest);
  throw std::invalid_argument("unknown experiment '" + args[0] + "' (expected " + expected + ")");
}

}  // namespace semsegmap::app
