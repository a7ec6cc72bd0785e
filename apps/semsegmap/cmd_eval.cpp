// semsegmap eval <experiment>: the paper's experiments as commands (eval/*_experiment.h), each
// printing its table and writing JSON and pictures; `eval paper` runs all three and writes
// report.md.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <optional>
#include <set>
#include <sstream>

#include "cli_args.h"
#include "dataset_args.h"
#include "eval_args.h"
#include "interrupt.h"
#include "progress.h"
#include "resources.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/describe/descriptor.h"
#include "semsegmap/eval/fleet_experiment.h"
#include "semsegmap/eval/report.h"
#include "semsegmap/settings/config.h"

namespace semsegmap::app {

namespace {

// --query-runs: a list of runs, each one of S0..S3.
std::vector<std::string> runList(const CliArgs& a, const std::string& name) {
  const std::vector<std::string> runs = splitList(a.get(name));
  for (const std::string& run : runs)
    if (run != "S0" && run != "S1" && run != "S2" && run != "S3")
      throw UsageError("option --" + name + ": unknown run '" + run + "' (expected S0..S3)");
  return runs;
}

// --descriptors: a list of descriptor names, checked before any experiment starts: a name that
// is none is a usage error, one this build does not have (descriptorNotBuilt) a runtime error.
std::vector<std::string> descriptorList(const CliArgs& a) {
  const std::vector<std::string> names = splitList(a.get("descriptors"));
  for (const std::string& name : names) {
    DescriptorKind kind = DescriptorKind::kEigen;
    try {
      kind = parseDescriptorKind(name);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("option --descriptors: ") + e.what());
    }
    const std::string missing = descriptorNotBuilt(kind);
    if (!missing.empty())
      throw std::runtime_error("option --descriptors: " + name + ": " + missing);
  }
  return names;
}

// The default of --descriptors: every descriptor this build has, the learned ones first.
std::string builtDescriptors() {
  std::string list;
  for (const DescriptorKind kind :
       {DescriptorKind::kSemSegMapNet, DescriptorKind::kSegMapCnn, DescriptorKind::kSmoothNetBow,
        DescriptorKind::kFpfh, DescriptorKind::kEigen})
    if (descriptorNotBuilt(kind).empty()) list += (list.empty() ? "" : ",") + descriptorName(kind);
  return list;
}

SegmentationExperimentConfig segmentationConfig(const CliArgs& a) {
  SegmentationExperimentConfig c;
  c.world_seed = a.getCount("world-seed");
  c.preset = a.get("preset");
  c.run = a.get("segmentation-run");
  c.max_frames = a.frameLimit();
  c.configs = comparedConfigs(a);
  return c;
}

DescriptorExperimentConfig descriptorConfig(const CliArgs& a) {
  DescriptorExperimentConfig c;
  c.world_seed = a.getCount("world-seed");
  c.preset = a.get("preset");
  c.run = a.get("descriptor-run");
  c.max_frames = a.frameLimit();
  c.descriptors = descriptorList(a);
  c.segmentation = loadNamedConfig(a.getPath("config"));
  c.models = a.getPath("models");
  c.threads = static_cast<int>(a.getCount("threads"));
  c.wake_up_every = a.getCount("wake-up-every");
  c.completeness_window = a.getCount("completeness-window");
  if (c.completeness_window == 0)
    throw UsageError("--completeness-window: a window of at least one frame");
  return c;
}

// --labels A+B+...: a pass per spec on the same rendered frames; the first pass's files go into
// the output folder, each other's into a folder named after its spec (network,rate=2 ->
// network_rate-2).
void setLabels(LocalizationExperimentConfig& c, const std::string& specs) {
  c.label_passes.clear();
  std::set<std::string> seen;
  for (const std::string& spec : splitList(specs, '+')) {
    if (!seen.insert(spec).second) throw UsageError("--labels: '" + spec + "' is given twice");
    LabelPass pass = labelPass(spec);
    if (!c.label_passes.empty()) {
      std::string dir = spec;
      std::replace(dir.begin(), dir.end(), ',', '_');
      std::replace(dir.begin(), dir.end(), '=', '-');
      std::replace(dir.begin(), dir.end(), '/', '-');
      pass.dir = dir;
    }
    c.label_passes.push_back(std::move(pass));
  }
  if (c.label_passes.empty()) throw UsageError("--labels: no label pass given");
  c.class_maps_dir = shippedFile("config/class_maps");
}

LocalizationExperimentConfig localizationConfig(const CliArgs& a) {
  LocalizationExperimentConfig c;
  c.world_seed = a.getCount("world-seed");
  c.preset = a.get("preset");
  c.map_run = a.get("map-run");
  c.query_runs = runList(a, "query-runs");
  c.max_frames = a.frameLimit();
  c.configs = comparedConfigs(a);
  // A describer this build does not have fails here, before the first frame.
  for (const NamedConfig& config : c.configs)
    requireDescriberBuilt(config.config.descriptor, config.path.string());
  if (a.command().name != "eval localization") return c;  // the paper's setting otherwise
  c.label_noise = static_cast<int>(a.getCount("label-noise"));
  if (c.label_noise > 3) throw UsageError("--label-noise is 0 (perfect labels) to 3");
  setLabels(c, a.get("labels"));
  if (c.label_noise > 0 && std::any_of(c.label_passes.begin(), c.label_passes.end(),
                                       [](const LabelPass& p) { return !p.network.model.empty(); }))
    throw UsageError(
        "--label-noise and --labels network: the network's labels replace the "
        "simulator's, noisy or not; give one of them");
  if (a.has("rig")) c.rig = a.get("rig");
  const std::string odometry = a.get("odometry");
  if (odometry != "simulated" && odometry != "lidar")
    throw UsageError("--odometry expects simulated or lidar, got '" + odometry + "'");
  c.lidar_odometry = odometry == "lidar";
  // LiDAR odometry takes the odometry: section of the first configuration.
  if (c.lidar_odometry) c.odometry = loadOdometryConfig(c.configs.front().path);
  return c;
}

// Each experiment runs with Ctrl-C's stop token (interrupt.h): stopped before its first frame it
// writes nothing; stopped later it writes what it did as whole files marked interrupted, prints
// its table and one line on stderr, and returns 130.
int experimentEnd(const CliArgs& a, bool interrupted, const StageProgress& progress) {
  return interrupted ? interruptedStages(a.command().name, progress, a.get("out")) : 0;
}

int runEvalSegmentation(const CliArgs& a) {
  const std::filesystem::path out = a.get("out");
  SegmentationExperimentConfig c = segmentationConfig(a);
  c.stop = stopToken();
  StageProgress progress;
  const SegmentationExperiment e = evaluateSegmentation(c, std::ref(progress));
  if (e.interrupted && !progress.started()) return experimentEnd(a, true, progress);
  writeSegmentationFiles(e, out);
  std::cout << segmentationTable(e) << "wrote " << (out / "segmentation.json").string()
            << ", segmentation.png\n";
  return experimentEnd(a, e.interrupted, progress);
}

int runEvalDescriptors(const CliArgs& a) {
  const std::filesystem::path out = a.get("out");
  DescriptorExperimentConfig c = descriptorConfig(a);
  c.stop = stopToken();
  StageProgress progress;
  const DescriptorExperiment e = evaluateDescriptors(c, std::ref(progress));
  if (e.interrupted && !progress.started()) return experimentEnd(a, true, progress);
  writeDescriptorFiles(e, out);
  std::cout << descriptorTable(e) << "\n"
            << completenessTable(e) << "wrote " << (out / "descriptors.json").string()
            << ", descriptors.png, completeness.png\n";
  return experimentEnd(a, e.interrupted, progress);
}

int runEvalLocalization(const CliArgs& a) {
  const std::filesystem::path out = a.get("out");
  LocalizationExperimentConfig c = localizationConfig(a);
  c.stop = stopToken();
  StageProgress progress;
  const LocalizationExperiment e = evaluateLocalization(c, out, std::ref(progress));
  if (e.interrupted && !progress.started()) return experimentEnd(a, true, progress);
  writeLocalizationFiles(e, out);
  std::cout << localizationTable(e) << "wrote " << (out / "localization.json").string()
            << ", localization_accuracy.png and one folder per run\n";
  return experimentEnd(a, e.interrupted, progress);
}

// [fleet]: the runs as sessions on LiDAR odometry, joined into one map, judged against the truth.
int runEvalFleet(const CliArgs& a) {
  const std::filesystem::path out = a.get("out");
  FleetExperimentConfig c;
  c.world_seed = a.getCount("world-seed");
  c.preset = a.get("preset");
  c.max_frames = a.frameLimit();
  c.config = a.getPath("config");
  c.sessions = splitList(a.get("sessions"));
  c.queries = {a.get("fifth-run")};
  c.stop = stopToken();
  StageProgress progress;
  c.progress = std::ref(progress);
  const FleetExperiment e = runFleetExperiment(c);
  if (e.interrupted && !progress.started()) return experimentEnd(a, true, progress);
  writeFleetExperiment(e, out);
  std::cout << fleetTable(e) << "wrote " << (out / "fleet.json").string()
            << ", fleet.md, fleet.map, fleet.png\n";
  return experimentEnd(a, e.interrupted, progress);
}

// The three experiments in turn; after Ctrl-C no further one starts, and report.md shows those
// that ran, saying it is partial.
int runEvalPaper(const CliArgs& a) {
  const std::filesystem::path out = a.get("out");
  const auto start = std::chrono::steady_clock::now();
  // Every configuration and model is read before the first experiment starts.
  SegmentationExperimentConfig sc = segmentationConfig(a);
  DescriptorExperimentConfig dc = descriptorConfig(a);
  LocalizationExperimentConfig lc = localizationConfig(a);
  sc.stop = dc.stop = lc.stop = stopToken();
  StageProgress progress;
  const SegmentationExperiment s = evaluateSegmentation(sc, std::ref(progress));
  if (s.interrupted && !progress.started()) return experimentEnd(a, true, progress);
  writeSegmentationFiles(s, out);
  std::cout << segmentationTable(s) << "\n";
  std::optional<DescriptorExperiment> d;
  std::optional<LocalizationExperiment> l;
  if (!s.interrupted) {
    d = runDescriptorExperiment(dc, out, std::ref(progress));
    std::cout << descriptorTable(*d) << "\n";
  }
  if (d && !d->interrupted) {
    l = runLocalizationExperiment(lc, out, std::ref(progress));
    std::cout << localizationTable(*l) << "\n";
  }
  ReportContext context;
  context.title = "SemSegMap against SegMap: the paper's experiments on world " +
                  std::to_string(sc.world_seed) + " (" + sc.preset + ")";
  context.command = "semsegmap eval paper";
  for (const std::string& arg : a.args()) context.command += " " + arg;
  context.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  context.interrupted = s.interrupted || (d && d->interrupted) || (l && l->interrupted);
  writeBytesAtomically(out / "report.md",
                       paperReport(context, &s, d ? &*d : nullptr, l ? &*l : nullptr));
  std::cout << "wrote " << (out / "report.md").string() << "\n";
  return experimentEnd(a, context.interrupted, progress);
}

// The options of the experiments, each declared once.
const OptionSpec kWorldSeed{"world-seed", Value::kCount, "N", "1", "seed of the procedural world"};
const OptionSpec kOut{"out", Value::kText, "DIR", "", "output folder", kRequired};
const OptionSpec kPreset{"preset", Value::kText, "full|small|tiny", "full", "size of the world"};
const OptionSpec kMaxFrames = maxFramesOption("stop each run after its first K frames, 0: all");
const OptionSpec kConfigs{
    "configs", Value::kText, "A.yaml,B.yaml", "config/semsegmap.yaml,config/segmap.yaml",
    "the configurations compared, SemSegMap first, the baseline second (default: the "
    "shipped ones)"};
const OptionSpec kSegmentationRun{"segmentation-run", Value::kText, "S0|S1|S2|S3", "S1",
                                  "the run whose revisits are compared"};
const OptionSpec kDescriptorRun{"descriptor-run", Value::kText, "S0|S1|S2|S3", "S0",
                                "the run whose segments are ranked"};
const OptionSpec kConfig{
    "config", Value::kText, "FILE", "config/semsegmap.yaml",
    "the configuration that cuts the descriptor run into segments (default: shipped)"};
const OptionSpec kModels{"models", Value::kText, "DIR", "models",
                         "folder of the learned descriptors' models (default: the shipped models)"};
const OptionSpec kDescriptors{"descriptors", Value::kText, "LIST", builtDescriptors(),
                              "the descriptors compared, of those this build has"};
const OptionSpec kWakeUpEvery{"wake-up-every", Value::kCount, "N", "5",
                              "one-scan wake-ups on every N-th frame of S2, 0: none"};
const OptionSpec kCompletenessWindow{
    "completeness-window", Value::kCount, "FRAMES", "10",
    "window of the run-time completeness estimate (a segment's growth over it)"};
const OptionSpec kThreads{"threads", Value::kCount, "N", "0",
                          "threads that describe segments, 0: all cores"};
const OptionSpec kMapRun{"map-run", Value::kText, "S0|S1|S2|S3", "S0",
                         "the run the target map is built from"};
const OptionSpec kQueryRuns{"query-runs", Value::kText, "LIST", "S2,S3",
                            "the runs localized against the map"};
const OptionSpec kLabelNoise{"label-noise", Value::kCount, "L", "0",
                             "camera labels as a segmentation network's, 0 (perfect) to 3"};
const OptionSpec kLabels{
    "labels", Value::kText, "SPEC", "perfect",
    "camera labels: perfect (the simulator's), or network[,rate=R][,budget=C][,every]"
    "[,ground=classes|geometry][,descriptor=own][,config=FILE]: the shipped segmentation "
    "network's on its "
    "budget, at R pictures a second per camera, within C cores, or on every picture, the ground "
    "removed by class alone or by geometry too, SemSegMap described by the network file's "
    "descriptor (trained on its labels) or its own (descriptor=own); several joined by + run on "
    "the same frames"};
const OptionSpec kRig{"rig", Value::kText, "KEYS", "",
                      "simulator keys for every run's rig, e.g. lidar=hdl64,cameras=front"};
const OptionSpec kQueryOdometry{
    "odometry", Value::kText, "simulated|lidar", "simulated",
    "the query runs' odometry: the simulator's drifting one, or LiDAR odometry on their scans"};

}  // namespace

const std::vector<const CommandSpec*>& simulatedEvalCommands() {
  static const CommandSpec segmentation{
      "eval segmentation",
      "segment consistency at revisits (convex hull IoU) -> segmentation.json",
      {kWorldSeed, kOut, kPreset, kMaxFrames, kConfigs, kSegmentationRun},
      "",
      runEvalSegmentation,
      /*stops_between_frames=*/true};
  static const CommandSpec descriptors{
      "eval descriptors",
      "retrieval of segments from their partial observations -> descriptors.json",
      {kWorldSeed, kOut, kPreset, kMaxFrames, kConfig, kModels, kDescriptors, kThreads,
       kDescriptorRun, kWakeUpEvery, kCompletenessWindow},
      "",
      runEvalDescriptors,
      /*stops_between_frames=*/true};
  static const CommandSpec localization{
      "eval localization",
      "maps one run, localizes the others with each config -> localization.json",
      {kWorldSeed, kOut, kPreset, kMaxFrames, kConfigs, kMapRun, kQueryRuns, kLabelNoise, kLabels,
       kQueryOdometry, kRig},
      "",
      runEvalLocalization,
      /*stops_between_frames=*/true};
  static const CommandSpec fleet{
      "eval fleet",
      "the runs as sessions on LiDAR odometry merged into one map, against the truth -> "
      "fleet.json",
      {kWorldSeed,
       kOut,
       {"preset", Value::kText, "full|small|tiny", "small", "size of the world"},
       kMaxFrames,
       {"config", Value::kText, "FILE", "config/semsegmap.yaml",
        "the pipeline configuration (default: shipped)"},
       {"sessions", Value::kText, "LIST", "S0,S1,S2,S3",
        "the runs joined in turn, the first the map's frame"},
       {"fifth-run", Value::kText, "RUN[,KEYS]", "S0,traffic=7",
        "the run localized against the merged map and the first session's alone"}},
      "",
      runEvalFleet,
      /*stops_between_frames=*/true};
  static const CommandSpec paper{
      "eval paper",
      "the segmentation, descriptor and localization experiments, and report.md",
      {kWorldSeed, kOut, kPreset, kMaxFrames, kConfigs, kSegmentationRun, kConfig, kModels,
       kDescriptors, kThreads, kDescriptorRun, kWakeUpEvery, kCompletenessWindow, kMapRun,
       kQueryRuns},
      "",
      runEvalPaper,
      /*stops_between_frames=*/true};
  static const std::vector<const CommandSpec*> all = {&segmentation, &descriptors, &localization,
                                                      &fleet, &paper};
  return all;
}

}  // namespace semsegmap::app
