// semsegmap demo: the main job on simulated data. On the small world: an overview picture, a
// target map from S0, and S2 (same light) and S3 (sunrise) localized against it with SemSegMap
// and the SegMap baseline on the same frames; the table on stdout, report.md and pictures in
// the output folder. Uses only files in the repository (configs and shipped models).
#include <chrono>
#include <filesystem>
#include <iostream>

#include "cli_args.h"
#include "progress.h"
#include "semsegmap/eval/report.h"
#include "semsegmap/io/atomic_file.h"
#include "semsegmap/sim/simulator.h"
#include "semsegmap/viz/sim_overview.h"

namespace semsegmap::app {

int runDemo(const std::vector<std::string>& args) {
  const CliArgs a(args, {"out", "world-seed", "preset", "max-frames", "configs"}, {});
  const auto start = std::chrono::steady_clock::now();
  const std::filesystem::path out = a.get("out", "demo_out");
  std::filesystem::create_directories(out);

  LocalizationExperimentConfig config;
  config.world_seed = static_cast<uint64_t>(a.getInt("world-seed", 1));
  config.preset = a.get("preset", "small");
  const long long max_frames = a.getInt("max-frames", 0);
  if (max_frames < 0) throw std::invalid_argument("--max-frames must not be negative");
  config.max_frames = static_cast<size_t>(max_frames);
  for (const char* path : {"config/semsegmap.yaml", "config/segmap.yaml"}) {
    if (!std::filesystem::exists(path))
      throw std::runtime_error(std::string(path) +
                               ": not found (run the demo from the repository's root)");
    config.configs.push_back(loadNamedConfig(path));
  }

  std::cout << "semsegmap demo: world " << config.world_seed << " (" << config.preset
            << "), map S0, localize S2 (sunny) and S3 (sunrise) with SemSegMap and SegMap\n";
  viz::writeSimOverview(sim::worldPreset(config.preset, config.world_seed), out / "overview.png");
  StageProgress progress;
  const LocalizationExperiment e = runLocalizationExperiment(config, out, std::ref(progress));
  std::cout << "\n" << localizationTable(e) << "\n";

  ReportContext context;
  context.title = "semsegmap demo: localization on the " + config.preset + " world " +
                  std::to_string(config.world_seed);
  context.command = "semsegmap demo";
  for (const std::string& arg : args) context.command += " " + arg;
  context.pictures = {"overview.png"};
  context.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  writeBytesAtomically(out / "report.md", paperReport(context, nullptr, nullptr, &e));
  std::printf("wrote %s with its pictures in %.1f min\n", (out / "report.md").string().c_str(),
              context.seconds / 60.0);
  return 0;
}

}  // namespace semsegmap::app
