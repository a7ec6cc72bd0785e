// Reproducible runs: the same command on the same inputs writes the same files, whatever the
// thread count. Three runs of `map` and `localize` through the built binary on the tiny world,
// one of them with OpenMP on a single thread, are compared byte for byte (summary.json without
// its timings, the only thing that may differ); the learned describer's own threads are checked
// directly.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "command_result.h"
#include "semsegmap/describe/learned_describer.h"
#include "semsegmap/describe/learned_net.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using semsegmap::test_support::readFile;

namespace {

// Runs `env BINARY args` from the source folder (the shipped configs name models/ relative to
// it); stdout and stderr go to files beside the outputs.
int run(const std::string& env, const std::string& args, const fs::path& log) {
  const std::string command = "cd '" SEMSEGMAP_SOURCE_DIR "' && " + env +
                              " '" SEMSEGMAP_BINARY "' " + args + " > '" + log.string() + "' 2>&1";
  return std::system(command.c_str());
}

// A map of the tiny world's S2 loop (its first 50 frames) and the localization of S2 at sunrise
// with other traffic against it, into `dir`.
void mapAndLocalize(const std::string& env, const fs::path& dir) {
  fs::create_directories(dir);
  const std::string config = " --config config/semsegmap.yaml";
  ASSERT_EQ(run(env,
                "map --dataset sim:world=1,run=S2,preset=tiny --max-frames 50 --points 16" +
                    config + " --out '" + (dir / "s0.map").string() + "'",
                dir / "map.log"),
            0)
      << readFile(dir / "map.log");
  ASSERT_EQ(run(env,
                "localize --dataset sim:world=1,run=S2,preset=tiny,condition=sunrise,traffic=9 "
                "--max-frames 30" +
                    config + " --map '" + (dir / "s0.map").string() + "' --out '" +
                    (dir / "loc").string() + "'",
                dir / "localize.log"),
            0)
      << readFile(dir / "localize.log");
}

// Segments of random coloured points in a 2 m box, a different size each.
std::vector<semsegmap::EnrichedCloud> randomSegments(int count) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<semsegmap::EnrichedCloud> segments;
  for (int i = 0; i < count; ++i) {
    semsegmap::EnrichedCloud cloud(static_cast<size_t>(100 + 13 * i));
    for (semsegmap::EnrichedPoint& p : cloud) {
      p.x = 2 * u(rng), p.y = 2 * u(rng), p.z = 2 * u(rng);
      p.h = u(rng), p.s = u(rng), p.v = u(rng), p.has_color = p.has_class = true;
      p.class_id = static_cast<semsegmap::ClassId>(1 + i % 5);
    }
    segments.push_back(std::move(cloud));
  }
  return segments;
}

nlohmann::json summaryWithoutTimings(const fs::path& path) {
  nlohmann::json summary = nlohmann::json::parse(readFile(path));
  summary.erase("fps");
  summary.erase("stage_ms");
  summary.erase("map");  // the map's path, which differs by folder
  return summary;
}

}  // namespace

// A descriptor changes in its last bits with the other segments of its chunk, so the chunks
// must not follow the thread count: 1, 2 and 5 threads give the same bits.
TEST(Determinism, LearnedDescriptorsDoNotDependOnTheThreadCount) {
  using namespace semsegmap;
  const std::vector<EnrichedCloud> segments = randomSegments(150);
  std::vector<DescriptorInput> batch;
  for (const EnrichedCloud& s : segments) batch.push_back({&s});
  for (const DescriptorKind kind : {DescriptorKind::kSemSegMapNet, DescriptorKind::kSegMapCnn}) {
    SCOPED_TRACE(descriptorName(kind));
    torch::manual_seed(5);
    NetConfig config;
    config.kind = kind;
    const auto net = makeNet(config);
    const Eigen::MatrixXf one = makeLearnedDescriber(kind, {net, 1})->describe(batch);
    ASSERT_EQ(one.rows(), 150);
    ASSERT_TRUE(one.allFinite());
    for (const int threads : {2, 5})
      EXPECT_EQ(makeLearnedDescriber(kind, {net, threads})->describe(batch), one)
          << threads << " threads";
  }
}

TEST(Determinism, SameCommandSameFilesWhateverTheThreadCount) {
  const semsegmap::test_support::TempDir tmp;
  const fs::path a = tmp.path() / "a", b = tmp.path() / "b", one = tmp.path() / "one_thread";
  mapAndLocalize("", a);
  mapAndLocalize("", b);
  mapAndLocalize("OMP_NUM_THREADS=1", one);
  if (HasFatalFailure()) return;
  const std::string map = readFile(a / "s0.map");
  ASSERT_GT(map.size(), 1000u) << "the map should hold segments";
  for (const fs::path& other : {b, one}) {
    SCOPED_TRACE(other.filename().string());
    EXPECT_EQ(readFile(other / "s0.map"), map);
    for (const char* file : {"localizations.csv", "matches.csv", "trajectory.csv"})
      EXPECT_EQ(readFile(other / "loc" / file), readFile(a / "loc" / file)) << file;
    EXPECT_EQ(summaryWithoutTimings(other / "loc" / "summary.json"),
              summaryWithoutTimings(a / "loc" / "summary.json"));
  }
  // Something was localized, or the comparison says little.
  EXPECT_GT(summaryWithoutTimings(a / "loc" / "summary.json")["n_localizations"].get<int>(), 5);
}

// The segmentation network on a budget, replayed on the data's clock: a third of a core and
// 25 ms a picture labels some pictures and carries their labels to the scans between, the same
// way on every run, so `map` and `localize` write the same files again.
TEST(Determinism, TheNetworksBudgetReplaysTheSameFiles) {
  const semsegmap::test_support::TempDir tmp;
  const fs::path source = SEMSEGMAP_SOURCE_DIR;
  std::string yaml = readFile(source / "config" / "semsegmap.yaml");
  const std::string models = "../models/";
  yaml.replace(yaml.find(models), models.size(), (source / "models").string() + "/");
  yaml += "semantics:\n  model: " + (source / "models" / "semsegmap-seg.onnx").string() +
          "\n  class_map: semsegmap\n  input_width: 320\n  input_height: 240\n"
          "  threads: 1\n  replace_dataset_labels: true\n"
          "  budget_cores: 0.3\n  latency_s: 0.025\n  tolerance_s: 0.5\n";
  const fs::path config = tmp.path() / "network.yaml";
  std::ofstream(config) << yaml;
  std::vector<std::string> maps;
  for (const char* name : {"a", "b"}) {
    const fs::path dir = tmp.path() / name;
    fs::create_directories(dir);
    ASSERT_EQ(run("",
                  "map --dataset sim:world=1,run=S2,preset=tiny --max-frames 25 --points 16"
                  " --config '" +
                      config.string() + "' --out '" + (dir / "s2.map").string() + "'",
                  dir / "map.log"),
              0)
        << readFile(dir / "map.log");
    maps.push_back(readFile(dir / "s2.map"));
  }
  ASSERT_GT(maps[0].size(), 1000u) << "the map should hold segments";
  EXPECT_EQ(maps[1], maps[0]);
  // The budget did what it is for: some pictures were not labelled, their scans took earlier
  // labels.
  const std::string log = readFile(tmp.path() / "a" / "map.log");
  const size_t at = log.find("an earlier picture's ");
  ASSERT_NE(at, std::string::npos) << log;
  EXPECT_GT(std::stoi(log.substr(at + 21)), 0) << log;
}
