// semsegmap demo: the main job on simulated data. On the small world: an overview picture, a
// target map from S0, and S2 (same light) and S3 (sunrise) localized against it with SemSegMap
// and the SegMap baseline on the same frames; the table on stdout, report.md and pictures in
// the output folder, with view.html, the S3 localization in 3D (semsegmap view). Uses only files
// in the repository (configs and shipped models).
#include <chrono>
#include <filesystem>
#include <iostream>

#include "cli_args.h"
#include "eval_args.h"
#include "interrupt.h"
#include "progress.h"
#include "resources.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/eval/localization_files.h"
#include "semsegmap/eval/report.h"
#include "semsegmap/settings/config.h"
#include "semsegmap/sim/simulator.h"
#include "semsegmap/viz/sim_overview.h"
#if SEMSEGMAP_WITH_VIEWER
#include "viewer_asset.h"
#endif

namespace semsegmap::app {

namespace {

// view.html: the 3D view of the first configuration's (SemSegMap's) S3 localization, the
// reversed run at sunrise; its file name, or nothing in a build without the viewer.
std::string writeDemoView(const LocalizationExperiment& e, const std::filesystem::path& out) {
#if SEMSEGMAP_WITH_VIEWER
  for (const LocalizationResult& r : e.results) {
    if (r.run != "S3" || r.config != e.config.configs.front().name) continue;
    ViewSources s;
    s.map = builtMapPath(out, e.config.configs.front());
    s.localization = out / r.dir;
    s.title = "demo: " + r.run + " against the " + e.config.map_run + " map, " + r.config;
    writeViewPage(s, out / "view.html");
    return "view.html";
  }
#else
  (void)e;
  (void)out;
#endif
  return "";
}

// The same runs with the camera labels of the shipped segmentation network at its shipped
// budget as well as the simulator's perfect ones (the paper's whole pipeline), on the same
// rendered frames: their rows join the table, their files go to out/network/.
void addNetworkPass(LocalizationExperimentConfig& config) {
  LabelPass pass = labelPass("network");
  pass.dir = "network";
  config.label_passes.push_back(std::move(pass));
  config.class_maps_dir = shippedFile("config/class_maps");
}

int runDemo(const CliArgs& a) {
  const auto start = std::chrono::steady_clock::now();
  const std::filesystem::path out = a.get("out");

  LocalizationExperimentConfig config;
  config.world_seed = a.getCount("world-seed");
  config.preset = a.get("preset");
  config.max_frames = a.frameLimit();
  for (const char* name : {"config/semsegmap.yaml", "config/segmap.yaml"}) {
    config.configs.push_back(loadNamedConfig(shippedFile(name)));
    // Their learned descriptors need libtorch: a build without it says so before it starts.
    requireDescriberBuilt(config.configs.back().config.descriptor, name);
  }
  addNetworkPass(config);
  std::filesystem::create_directories(out);

  const SemanticsConfig& network = config.label_passes.back().network;
  std::cout << "semsegmap demo: world " << config.world_seed << " (" << config.preset
            << "), map S0, localize S2 (sunny) and S3 (sunrise) with SemSegMap and SegMap,\n"
            << "with the simulator's perfect camera labels and with the shipped segmentation "
               "network's (within "
            << network.budget_cores << " of a core"
            << (config.label_passes.back().geometric_ground_removal
                    ? ", the ground removed by geometry too"
                    : "")
            << (network.rate_hz > 0
                    ? ", at most " + std::to_string(network.rate_hz) + " pictures a second a camera"
                    : "")
            << (config.label_passes.back().descriptor_model.empty()
                    ? ""
                    : ", SemSegMap's segments described by the descriptor trained on its labels")
            << ")\n";
  viz::writeSimOverview(sim::worldPreset(config.preset, config.world_seed), out / "overview.png");
  config.stop = stopToken();
  StageProgress progress;
  LocalizationExperiment e = evaluateLocalization(config, out, std::ref(progress));
  // Ctrl-C before the first frame: nothing worth keeping (main removes the folder's new files).
  if (e.interrupted && !progress.started()) return interruptedStages("demo", progress, "");
  writeLocalizationFiles(e, out);
  std::cout << "\n" << localizationTable(e) << "\n";

  ReportContext context;
  context.title = "semsegmap demo: localization on the " + config.preset + " world " +
                  std::to_string(config.world_seed);
  context.command = "semsegmap demo";
  for (const std::string& arg : a.args()) context.command += " " + arg;
  context.pictures = {"overview.png"};
  context.view = writeDemoView(e, out);
  context.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  context.interrupted = e.interrupted;
  writeBytesAtomically(out / "report.md", paperReport(context, nullptr, nullptr, &e));
  std::printf("wrote %s with its pictures in %.1f min\n", (out / "report.md").string().c_str(),
              context.seconds / 60.0);
  return e.interrupted ? interruptedStages("demo", progress, out.string()) : 0;
}

}  // namespace

const CommandSpec& demoCommand() {
  static const CommandSpec command{
      "demo",
      "the main job: map S0, localize S2 and S3 with SemSegMap and SegMap -> report.md",
      {
          {"out", Value::kText, "DIR", "demo_out", "output folder: report.md and pictures"},
          {"world-seed", Value::kCount, "N", "1", "seed of the procedural world"},
          {"preset", Value::kText, "full|small|tiny", "small", "size of the world"},
          maxFramesOption("stop each run after its first K frames, 0: all"),
      },
      "It reads the shipped config/semsegmap.yaml, config/segmap.yaml and models, from the\n"
      "installed share/semsegmap or the source tree, wherever it is run from.\n",
      runDemo,
      /*stops_between_frames=*/true};
  return command;
}

}  // namespace semsegmap::app
