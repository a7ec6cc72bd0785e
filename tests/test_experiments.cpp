// The paper's experiments (eval/*_experiment.h): their metrics on known numbers, and each one end
// to end on the tiny world with its JSON read back (yaml-cpp reads JSON) and its pictures present.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>

#include "build_options.h"
#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/json.h"
#include "semsegmap/eval/fleet_experiment.h"
#include "semsegmap/eval/localization_metrics.h"
#include "semsegmap/eval/report.h"
#include "semsegmap/settings/config.h"
#include "temp_dir.h"

namespace semsegmap {
namespace {

using test_support::TempDir;

const std::string kSource = SEMSEGMAP_SOURCE_DIR;

std::vector<NamedConfig> bothConfigs() {
  return {loadNamedConfig(kSource + "/config/semsegmap.yaml"),
          loadNamedConfig(kSource + "/config/segmap.yaml")};
}

void expectPng(const std::filesystem::path& path) {
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
  EXPECT_EQ(readFileBytes(path).substr(1, 3), "PNG") << path;
}

TEST(LocalizationMetrics, CumulativeCountsOfAKnownErrorList) {
  const std::vector<double> errors = {0.2, 0.9, 0.2, 3.0, 12.0};
  EXPECT_EQ(cumulativeCounts(errors, {0.0, 0.2, 0.5, 1.0, 5.0, 100.0}),
            (std::vector<size_t>{0, 2, 2, 3, 4, 5}));
  EXPECT_TRUE(cumulativeCounts({}, {1.0}) == std::vector<size_t>{0});
}

TEST(LocalizationMetrics, RecallAlongTheTrajectory) {
  // 11 frames 10 m apart (100 m). A correct fix at frame 2 (20 m) covers the metres up to 40 m;
  // one at frame 7 (70 m) those up to 90 m: 20 + 20 of 100 m.
  std::vector<double> travelled;
  for (int i = 0; i <= 10; ++i) travelled.push_back(10.0 * i);
  EXPECT_NEAR(recallAlongTrajectory(travelled, {2, 7}, 20.0), 0.4, 1e-12);
  EXPECT_NEAR(recallAlongTrajectory(travelled, {7, 2, 2}, 20.0), 0.4, 1e-12);  // any order
  EXPECT_NEAR(recallAlongTrajectory(travelled, {}, 20.0), 0.0, 1e-12);
  std::vector<size_t> all(11);
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  EXPECT_NEAR(recallAlongTrajectory(travelled, all, 20.0), 1.0, 1e-12);
  EXPECT_EQ(recallAlongTrajectory({0.0}, {0}, 20.0), 0.0);  // no drive
  EXPECT_THROW(recallAlongTrajectory(travelled, {11}, 20.0), std::out_of_range);
  const std::vector<Pose> line = {planarPose(0, 0, 0, 0), planarPose(3, 4, 0, 1),
                                  planarPose(3, 4, 0, 2)};
  EXPECT_EQ(travelledDistances(line), (std::vector<double>{0.0, 5.0, 5.0}));
}

// Names are written escaped: configuration, descriptor, dataset and directory names with a quote
// and a backslash read back from every experiment's JSON as they were.
TEST(Experiments, NamesWithQuotesAndBackslashesRoundTripThroughTheJson) {
  TempDir tmp;
  const std::string name = "my \"odd\" C:\\name";
  auto readBack = [&](const nlohmann::ordered_json& j) {
    writeJsonAtomically(tmp.path() / "e.json", j);
    return nlohmann::json::parse(readFileBytes(tmp.path() / "e.json"));
  };

  SegmentationExperiment s;
  s.config.preset = name;
  s.results.emplace_back().config = name;
  const nlohmann::json sj = readBack(toJson(s));
  EXPECT_EQ(sj["preset"], name);
  EXPECT_EQ(sj["results"][0]["config"], name);

  DescriptorExperiment d;
  d.dataset = name;
  d.bands = {{0.0, 1.0, name}};
  d.results.emplace_back().descriptor = name;
  const nlohmann::json dj = readBack(toJson(d));
  EXPECT_EQ(dj["dataset"], name);
  EXPECT_EQ(dj["bands"][0], name);
  EXPECT_EQ(dj["descriptors"][0]["name"], name);

  LocalizationExperiment l;
  l.config.map_run = name;
  LocalizationResult& r = l.results.emplace_back();
  r.config = r.descriptor = r.run = r.dataset = name;
  r.dir = name;
  const nlohmann::json lj = readBack(toJson(l));
  EXPECT_EQ(lj["map_run"], name);
  for (const char* key : {"config", "descriptor", "run", "dataset", "dir"})
    EXPECT_EQ(lj["results"][0][key], name) << key;
}

TEST(SegmentationExperiment, HistogramAndRelativeChange) {
  EXPECT_EQ(iouHistogram({0.0, 0.05, 0.1, 0.33, 0.99, 1.0}, 10),
            (std::vector<size_t>{2, 1, 0, 1, 0, 0, 0, 0, 0, 2}));
  EXPECT_THROW(iouHistogram({0.5}, 0), std::invalid_argument);
  EXPECT_DOUBLE_EQ(relativeChangePct(131, 100), 31.0);
  EXPECT_DOUBLE_EQ(relativeChangePct(75, 100), -25.0);
  EXPECT_DOUBLE_EQ(relativeChangePct(5, 0), 0.0);
}

// All three experiments on the tiny world (a few frames each), then the report that links them.
TEST(Experiments, EachRunsEndToEndAndTheReportShowsThem) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  SEMSEGMAP_SKIP_WITHOUT_TORCH();  // the shipped configurations' descriptors are learned
  TempDir tmp;
  const std::filesystem::path out = tmp.path();

  SegmentationExperimentConfig sc;
  sc.preset = "tiny";
  sc.max_frames = 400;  // the tiny S1 is back where it started after about 300 m
  sc.exclude_recent_m = 40.0;
  sc.configs = bothConfigs();
  const SegmentationExperiment s = runSegmentationExperiment(sc, out);
  const YAML::Node sj = YAML::LoadFile((out / "segmentation.json").string());
  ASSERT_EQ(sj["results"].size(), 2u);
  for (const auto& r : sj["results"]) {
    const size_t revisits = r["revisit_segments"].as<size_t>();
    EXPECT_GT(revisits, 0u) << r["config"].as<std::string>();
    EXPECT_EQ(r["consistent"].as<size_t>() + r["inconsistent"].as<size_t>(), revisits);
    size_t sum = 0;
    for (const auto& v : r["histogram"]) sum += v.as<size_t>();
    EXPECT_EQ(sum, revisits);
    EXPECT_GE(r["segments"].as<size_t>(), revisits);
  }
  EXPECT_EQ(sj["bin_change_pct"].size(), 10u);
  EXPECT_NEAR(sj["consistent_change_pct"].as<double>(), s.consistent_change_pct, 1e-3);
  EXPECT_DOUBLE_EQ(sj["paper"]["consistent_change_pct"].as<double>(), 30.97);
  expectPng(out / "segmentation.png");

  DescriptorExperimentConfig dc;
  dc.preset = "tiny";
  dc.max_frames = 50;
  dc.segmentation = bothConfigs()[0];
  dc.models = kSource + "/models";
  dc.descriptors = {"semsegmap-net", "eigen"};
  dc.threads = 2;
  const DescriptorExperiment d = runDescriptorExperiment(dc, out);
  const YAML::Node dj = YAML::LoadFile((out / "descriptors.json").string());
  ASSERT_EQ(dj["descriptors"].size(), 2u);
  EXPECT_EQ(dj["descriptors"][0]["name"].as<std::string>(), "semsegmap-net");
  EXPECT_GT(dj["queries"].as<size_t>(), 0u);
  for (const auto& r : dj["descriptors"]) {
    EXPECT_EQ(r["band_curves"].size(), 4u);
    EXPECT_EQ(r["estimated_band_curves"].size(), 4u);
    EXPECT_LE(r["top1"].as<double>(), r["top16"].as<double>());
  }
  expectPng(out / "descriptors.png");
  // The run-time completeness estimate: each window's agreement, the queries binned by it (every
  // query in some estimated band), and the one-scan wake-ups of S2 ranked by each descriptor.
  const YAML::Node cj = dj["completeness_estimate"];
  EXPECT_EQ(cj["window_frames"].as<size_t>(), dc.completeness_window);
  EXPECT_EQ(cj["windows"].size(), dc.completeness_windows.size());
  size_t binned = 0;
  for (const auto& n : dj["descriptors"][0]["estimated_band_counts"]) binned += n.as<size_t>();
  EXPECT_EQ(binned, dj["queries"].as<size_t>());
  EXPECT_EQ(d.wake_ups, 10u);  // frames 0, 5, ..., 45 of the first 50
  EXPECT_GT(d.wake_up_queries, 0u);
  ASSERT_EQ(dj["wake_ups"]["descriptors"].size(), 2u);
  EXPECT_GT(dj["wake_ups"]["descriptors"][0]["top16"].as<double>(), 0.0);
  expectPng(out / "completeness.png");

  LocalizationExperimentConfig lc;
  lc.preset = "tiny";
  lc.max_frames = 30;
  lc.configs = bothConfigs();
  const LocalizationExperiment l = runLocalizationExperiment(lc, out);
  const YAML::Node lj = YAML::LoadFile((out / "localization.json").string());
  ASSERT_EQ(lj["results"].size(), 4u);  // S2 and S3, two configurations each
  EXPECT_EQ(lj["thresholds_m"].size(), 101u);
  for (const auto& r : lj["results"]) {
    for (const char* key :
         {"n_localizations", "n_error_below_1m", "n_error_below_5m", "mean_translation_error_m",
          "mean_rotation_error_deg", "n_wrong", "wrong_rate", "recall_along_trajectory", "fps",
          "map_segments", "map_bytes"})
      EXPECT_TRUE(r[key].IsDefined()) << key;
    EXPECT_EQ(r["frames"].as<size_t>(), 30u);
    EXPECT_GT(r["map_segments"].as<size_t>(), 0u);
    EXPECT_GT(r["fps"].as<double>(), 0.0);
    const size_t n = r["n_localizations"].as<size_t>();
    EXPECT_EQ(r["cumulative"][100].as<size_t>() + r["n_wrong"].as<size_t>(), n);
    const std::string dir = r["dir"].as<std::string>();
    expectPng(out / dir / "localization.png");
    EXPECT_TRUE(std::filesystem::exists(out / dir / "localizations.csv"));
    EXPECT_TRUE(std::filesystem::exists(out / dir / "summary.json"));
  }
  // S2 drives where S0 drove: SemSegMap localizes there within its first 30 frames.
  EXPECT_GT(l.results[0].summary.localizations, 0u);
  EXPECT_TRUE(std::filesystem::exists(out / "maps" / "semsegmap.map"));
  expectPng(out / "localization_accuracy.png");

  ReportContext context;
  context.command = "test";
  const std::string report = paperReport(context, &s, &d, &l);
  for (const char* heading : {"## Segmentation consistency", "## Descriptor retrieval",
                              "## Localization", "## Configurations and models", "+30.97 %"})
    EXPECT_NE(report.find(heading), std::string::npos) << heading;
  // Every picture the report shows exists.
  for (size_t at = report.find("]("); at != std::string::npos; at = report.find("](", at + 1)) {
    const std::string link = report.substr(at + 2, report.find(')', at) - at - 2);
    EXPECT_TRUE(std::filesystem::exists(out / link)) << link;
  }
}

// The demo's two halves on one rendering: a network's pass beside the simulator's labels gives,
// file for file, what each pass gives alone, and says where its labels came from.
TEST(LocalizationExperiment, PassesOnTheSameFramesGiveWhatEachGivesAlone) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  SEMSEGMAP_SKIP_WITHOUT_TORCH();
  TempDir tmp;
  LabelPass network;
  network.labels = "network";
  network.network = loadSemanticsConfig(kSource + "/config/semantics-sim-network.yaml");
  network.geometric_ground_removal = true;  // as the shipped network's file says
  network.dir = "network";
  LocalizationExperimentConfig c;
  c.preset = "tiny";
  c.max_frames = 25;
  c.query_runs = {"S2"};
  c.configs = {bothConfigs()[0]};
  c.class_maps_dir = kSource + "/config/class_maps";
  c.label_passes = {LabelPass{}, network};
  const LocalizationExperiment both = evaluateLocalization(c, tmp.path() / "both");
  c.label_passes = {LabelPass{}};
  const LocalizationExperiment perfect = evaluateLocalization(c, tmp.path() / "perfect");
  network.dir = "";
  c.label_passes = {network};
  const LocalizationExperiment alone = evaluateLocalization(c, tmp.path() / "network");

  ASSERT_EQ(both.results.size(), 2u);
  EXPECT_EQ(both.results[0].labels, "perfect");
  EXPECT_EQ(both.results[1].labels, "network");
  EXPECT_EQ(both.results[1].dir, std::filesystem::path("network") / "semsegmap_S2");
  EXPECT_GT(both.results[1].labelling.network_runs, 0u);
  EXPECT_EQ(perfect.results[0].labelling.network_runs, 0u);
  const auto same = [&](const std::filesystem::path& a, const std::filesystem::path& b) {
    EXPECT_EQ(readFileBytes(tmp.path() / a), readFileBytes(tmp.path() / b)) << a << " " << b;
  };
  same("both/maps/semsegmap.map", "perfect/maps/semsegmap.map");
  same("both/network/maps/semsegmap.map", "network/maps/semsegmap.map");
  same("both/semsegmap_S2/localizations.csv", "perfect/semsegmap_S2/localizations.csv");
  same("both/network/semsegmap_S2/localizations.csv", "network/semsegmap_S2/localizations.csv");
  EXPECT_NE(readFileBytes(tmp.path() / "both/maps/semsegmap.map"),
            readFileBytes(tmp.path() / "both/network/maps/semsegmap.map"));
  EXPECT_EQ(both.results[1].labelling.network_runs, alone.results[0].labelling.network_runs);
  EXPECT_GT(both.results[0].map_segments, 0u);
  EXPECT_TRUE(toJson(both)["label_passes"][1]["geometric_ground_removal"].get<bool>());
  // The pass's ground removal is its own: by class alone, the network's map differs.
  network.geometric_ground_removal = false;
  c.label_passes = {network};
  evaluateLocalization(c, tmp.path() / "classes");
  EXPECT_NE(readFileBytes(tmp.path() / "classes/maps/semsegmap.map"),
            readFileBytes(tmp.path() / "network/maps/semsegmap.map"));
  // So is its descriptor: the model the network's file names describes the pass's segments.
  network.geometric_ground_removal = true;
  network.descriptor_kind = "semsegmap-net";
  network.descriptor_model = kSource + "/models/semsegmap-net-network.model";
  c.label_passes = {network};
  const LocalizationExperiment described = evaluateLocalization(c, tmp.path() / "described");
  EXPECT_NE(readFileBytes(tmp.path() / "described/maps/semsegmap.map"),
            readFileBytes(tmp.path() / "network/maps/semsegmap.map"));
  EXPECT_EQ(toJson(described)["label_passes"][0]["descriptor"]["model"].get<std::string>(),
            network.descriptor_model);
}

// [fleet]: two drives of one route on their own LiDAR odometry, the second joined to the first's
// map; the merged map's entries where the truth puts them (after one rigid alignment, since the
// map's frame is the first drive's odometry frame), and a third drive localized against both
// maps, counted in the world.
TEST(FleetExperiment, TwoDrivesMergeWhereTheTruthIsAndAThirdLocalizesInTheWorld) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  SEMSEGMAP_SKIP_WITHOUT_TORCH();
  FleetExperimentConfig c;
  c.preset = "tiny";
  c.max_frames = 60;
  c.sessions = {"S0", "S0,traffic=7"};
  c.queries = {"S0,traffic=3"};
  c.config = std::string(SEMSEGMAP_SOURCE_DIR) + "/config/semsegmap.yaml";
  const FleetExperiment e = runFleetExperiment(c);
  ASSERT_EQ(e.sessions.size(), 2u);
  EXPECT_TRUE(e.sessions[1].aligned);
  EXPECT_GE(e.sessions[1].ties, 3u);
  EXPECT_GT(e.sessions[1].same_segments, e.sessions[1].entries / 3);
  EXPECT_EQ(e.entries, e.sessions[0].entries + e.sessions[1].entries);
  EXPECT_LT(e.segments, e.entries);
  EXPECT_LT(e.centroid_mean_m, 0.5);
  EXPECT_LT(e.sessions[1].trajectory_error_m, 0.5);
  ASSERT_EQ(e.queries.size(), 1u);
  const FleetQuery& q = e.queries[0];
  EXPECT_GT(q.within_1m_merged, q.localizations_merged / 2);
  EXPECT_EQ(q.wrong_merged, 0u);
  EXPECT_GE(q.within_1m_merged + 2, q.within_1m_first);
  const auto j = toJson(e);
  EXPECT_EQ(j["sessions"].size(), 2u);
  EXPECT_NE(fleetTable(e).find("| S0,traffic=7 |"), std::string::npos);
  TempDir tmp;
  writeFleetExperiment(e, tmp.path());
  for (const char* f : {"fleet.json", "fleet.md", "fleet.png"})
    EXPECT_GT(std::filesystem::file_size(tmp.path() / f), 100u) << f;
  EXPECT_EQ(loadTargetMap(tmp.path() / "fleet.map").sessions.size(), 2u);
}

}  // namespace
}  // namespace semsegmap
