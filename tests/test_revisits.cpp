// The revisit experiment (eval/revisit_experiment.h): frame ranges, the checks made before any
// frame is read, and the experiment end to end on a simulated run that drives through the same
// street again and on the real KITTI revisits.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "build_options.h"
#include "error_text.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/eval/revisit_experiment.h"
#include "temp_dir.h"

namespace semsegmap {
namespace {

using test_support::errorOf;
using test_support::TempDir;

const std::string kSource = SEMSEGMAP_SOURCE_DIR;

// What revisits.json does not know is null: no scan registered (no correction measured), a
// localization whose scan did not register, a wake-up that never localized, a mean of nothing.
TEST(RevisitResults, UnknownValuesAreNullInTheJson) {
  RevisitExperiment e;
  RevisitResult& r = e.results.emplace_back();
  r.localizations.push_back({12, 7, 0.4, 1.0});  // registered errors -1: none
  r.wake_ups.push_back({{10, 14}, true, 0, false});
  const nlohmann::ordered_json j = toJson(e);
  EXPECT_TRUE(j["mean_ground_truth_correction_m"].is_null());
  EXPECT_TRUE(j["max_ground_truth_correction_m"].is_null());
  const nlohmann::ordered_json& result = j["results"][0];
  EXPECT_TRUE(result["mean_translation_error_m"].is_null());
  EXPECT_TRUE(result["mean_registered_error_m"].is_null());
  EXPECT_TRUE(result["ms_per_query"].is_null()) << "no query frame: no time";
  EXPECT_TRUE(result["localizations"][0]["registered_error_m"].is_null());
  EXPECT_DOUBLE_EQ(result["localizations"][0]["translation_error_m"].get<double>(), 0.4);
  EXPECT_TRUE(result["wake_ups"][0]["localized_at_frame"].is_null());
  EXPECT_NE(revisitTable(e).find("| - |"), std::string::npos) << revisitTable(e);
}

TEST(RevisitRanges, ParseListsAndSingleFrames) {
  const std::vector<FrameRange> r = parseFrameRanges("0:5,9,12:20", "--map-frames");
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0].first, 0u);
  EXPECT_EQ(r[0].last, 5u);
  EXPECT_EQ(r[1].first, 9u);
  EXPECT_EQ(r[1].last, 9u);
  EXPECT_EQ(r[2].last, 20u);
  for (const char* bad : {"", "5:3", "a:b", "1:", "-1:4", "3:4:5"}) {
    const std::string e = errorOf([&] { parseFrameRanges(bad, "--map-frames"); });
    EXPECT_MENTIONS(e, "--map-frames");
    EXPECT_ONE_LINE(e);
  }
}

TEST(RevisitRanges, WakeUpsSplitTheQueryRangesIntoFreshSessions) {
  RevisitExperimentConfig c;
  c.query_frames = parseFrameRanges("10:21,30:31", "query");
  EXPECT_EQ(querySessions(c).size(), 1u) << "without wake-ups one session over every range";
  parseWakeUp("3/5", "--wake-up", c);
  EXPECT_EQ(c.wake_up_frames, 3u);
  EXPECT_EQ(c.wake_up_every, 5u);
  const std::vector<std::vector<FrameRange>> s = querySessions(c);
  ASSERT_EQ(s.size(), 4u);  // 10:12, 15:17, 20:21 (cut at the range's end), 30:31
  EXPECT_EQ(s[0].front().first, 10u);
  EXPECT_EQ(s[0].front().last, 12u);
  EXPECT_EQ(s[2].front().last, 21u);
  EXPECT_EQ(s[3].front().first, 30u);
  parseWakeUp("1", "--wake-up", c);  // every query frame on its own
  EXPECT_EQ(querySessions(c).size(), 14u);
  for (const char* bad : {"", "0", "3/2", "a", "2/", "/4", "1/0"}) {
    const std::string e = errorOf([&] { parseWakeUp(bad, "--wake-up", c); });
    EXPECT_MENTIONS(e, "--wake-up");
    EXPECT_ONE_LINE(e);
  }
}

// A dataset that counts the frames read: the checks must refuse before the first one.
class CountingSource : public FrameSource {
 public:
  explicit CountingSource(bool ground_truth) {
    info_.name = "counted";
    info_.has_ground_truth_poses = ground_truth;
    info_.has_odometry = true;
  }
  const DatasetInfo& info() const override { return info_; }
  size_t size() const override { return 20; }
  Frame frame(size_t index) override {
    ++reads;
    Frame f;
    f.index = index;
    return f;
  }
  size_t reads = 0;

 private:
  DatasetInfo info_;
};

TEST(RevisitExperiment, RefusesBadRangesAndMissingGroundTruthBeforeReadingAFrame) {
  TempDir tmp;
  RevisitExperimentConfig cfg;
  cfg.configs = {loadNamedConfig(kSource + "/config/lidar-camera.yaml")};
  const auto refusal = [&](bool gt, const std::string& map, const std::string& query) {
    CountingSource source(gt);
    cfg.map_frames = parseFrameRanges(map, "map");
    cfg.query_frames = parseFrameRanges(query, "query");
    const std::string e = errorOf([&] { evaluateRevisits(source, cfg, tmp.path()); });
    EXPECT_EQ(source.reads, 0u) << e;
    EXPECT_ONE_LINE(e);
    return e;
  };
  EXPECT_MENTIONS(refusal(true, "0:9", "10:25"), "10:25 are beyond its 20 frames");
  EXPECT_MENTIONS(refusal(true, "0:9", "9:15"), "frame 9 is both mapped and queried");
  EXPECT_MENTIONS(refusal(false, "0:9", "10:15"), "needs ground-truth poses");
  // Scan Context's results are named scan-context: a configuration may not be.
  cfg.configs.front().name = "scan-context";
  EXPECT_MENTIONS(refusal(true, "0:9", "10:15"), "leave Scan Context out");
  cfg.configs.front().name = "lidar-camera";
  cfg.wake_up_frames = 2;
  EXPECT_MENTIONS(refusal(true, "0:9", "10:15,12:13"), "must not overlap each other");
}

void expectPng(const std::filesystem::path& path) {
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
  EXPECT_EQ(readFileBytes(path).substr(1, 3), "PNG") << path;
}

// S1 of the tiny world drives the street of its first 60 frames again from frame 395 on: the map
// from those 60, SemSegMap's configuration.
RevisitExperimentConfig tinyRevisit(const std::string& query_frames) {
  RevisitExperimentConfig cfg;
  cfg.map_frames = parseFrameRanges("0:59", "map");
  cfg.query_frames = parseFrameRanges(query_frames, "query");
  cfg.configs = {loadNamedConfig(kSource + "/config/semsegmap.yaml")};
  return cfg;
}

TEST(RevisitExperiment, LocalizesTheRevisitsOfASimulatedRun) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  SEMSEGMAP_SKIP_WITHOUT_TORCH();
  TempDir tmp;
  auto source = openDataset("sim:world=1,run=S1,preset=tiny");
  RevisitExperimentConfig cfg = tinyRevisit("395:460");
  cfg.check_ground_truth = true;
  const RevisitExperiment e = evaluateRevisits(*source, cfg, tmp.path());
  writeRevisitFiles(e, tmp.path());
  ASSERT_EQ(e.queries.size(), 66u);
  // The simulator's ground truth is exact: registration leaves it where it is.
  EXPECT_GT(e.registered, 40u);
  EXPECT_LT(e.mean_correction_m, 0.1);
  EXPECT_EQ(e.queries.front().frame, 395u);
  EXPECT_GT(e.revisits, 40u);
  ASSERT_EQ(e.results.size(), 2u) << "SemSegMap and Scan Context";
  const RevisitResult& r = e.results[0];
  EXPECT_GT(r.localizations.size(), 10u);
  EXPECT_GT(r.revisits_localized, 10u);
  EXPECT_EQ(r.wrong, 0u);
  for (const RevisitLocalization& l : r.localizations) {
    EXPECT_GE(l.frame, 395u) << "reported under the dataset's frame numbers";
    EXPECT_LE(l.frame, 460u);
  }
  const YAML::Node j = YAML::LoadFile((tmp.path() / "revisits.json").string());
  EXPECT_EQ(j["n_revisits"].as<size_t>(), e.revisits);
  EXPECT_EQ(j["results"][0]["n_localizations"].as<size_t>(), r.localizations.size());
  expectPng(tmp.path() / "revisits.png");
  expectPng(tmp.path() / "semsegmap" / "localization.png");
  EXPECT_TRUE(std::filesystem::exists(tmp.path() / "maps" / "semsegmap.map"));
  EXPECT_NE(revisitTable(e).find("| semsegmap | segments (semsegmap-net) |"), std::string::npos)
      << revisitTable(e);
  ASSERT_TRUE(r.ms_per_query.has_value());
  EXPECT_GT(*r.ms_per_query, 0.0);
  EXPECT_EQ(j["results"][0]["method"].as<std::string>(), "segments");

  // Scan Context on the same frames: the mapped scans at their ground-truth poses, each query
  // scan on its own; a row, a JSON result and a folder of its own.
  const RevisitResult& sc = e.results[1];
  EXPECT_EQ(sc.config, kScanContextName);
  EXPECT_EQ(sc.method, kScanContextName);
  EXPECT_EQ(sc.descriptor, kScanContextName);
  EXPECT_EQ(sc.mapped_scans, 60u);
  EXPECT_GT(sc.map_bytes, 0u);
  EXPECT_GE(sc.below_1m, 1u);
  EXPECT_EQ(sc.wrong, 0u);
  EXPECT_GE(sc.registered_compared, 1u) << "its errors against the registered ground truth too";
  for (const RevisitLocalization& l : sc.localizations) {
    EXPECT_GE(l.frame, 395u) << "reported under the dataset's frame numbers";
    EXPECT_LE(l.frame, 460u);
  }
  ASSERT_TRUE(sc.ms_per_query.has_value()) << "scan context, retrieval and registration, timed";
  EXPECT_GT(*sc.ms_per_query, 0.0);
  const std::string table = revisitTable(e);
  EXPECT_NE(table.find("| ms / query |"), std::string::npos) << table;
  EXPECT_NE(table.find("| scan-context | Scan Context (whole scan) | " +
                       std::to_string(sc.localizations.size()) + " |"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("scan-context: against the registered ground truth"), std::string::npos);
  EXPECT_EQ(j["results"][1]["config"].as<std::string>(), "scan-context");
  EXPECT_EQ(j["results"][1]["method"].as<std::string>(), "scan-context");
  EXPECT_GT(j["results"][1]["ms_per_query"].as<double>(), 0.0);
  for (const char* file : {"localizations.csv", "summary.json", "trajectory.csv"})
    EXPECT_TRUE(std::filesystem::exists(tmp.path() / "scan-context" / file)) << file;
  expectPng(tmp.path() / "scan-context" / "localization.png");
}

// Scan Context is on by default (the row above); asked to, the experiment leaves it out: no row,
// no folder.
TEST(RevisitExperiment, ScanContextCanBeLeftOut) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  SEMSEGMAP_SKIP_WITHOUT_TORCH();
  TempDir tmp;
  auto source = openDataset("sim:world=1,run=S1,preset=tiny");
  RevisitExperimentConfig cfg = tinyRevisit("10:11");
  cfg.map_frames = parseFrameRanges("0:9", "map");
  cfg.scan_context.reset();
  const RevisitExperiment e = evaluateRevisits(*source, cfg, tmp.path());
  writeRevisitFiles(e, tmp.path());
  ASSERT_EQ(e.results.size(), 1u);
  EXPECT_EQ(e.results[0].config, "semsegmap");
  EXPECT_EQ(revisitTable(e).find("scan-context"), std::string::npos) << revisitTable(e);
  EXPECT_FALSE(std::filesystem::exists(tmp.path() / "scan-context"));
  const YAML::Node j = YAML::LoadFile((tmp.path() / "revisits.json").string());
  EXPECT_EQ(j["results"].size(), 1u);
}

// The kidnapped robot: woken up every 15 frames of the revisit with an empty local map, it
// localizes from its first few frames; every wake-up is its own session.
TEST(RevisitExperiment, WakesUpWithAnEmptyLocalMapAndLocalizesWithinAFewFrames) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  SEMSEGMAP_SKIP_WITHOUT_TORCH();
  TempDir tmp;
  auto source = openDataset("sim:world=1,run=S1,preset=tiny");
  RevisitExperimentConfig cfg = tinyRevisit("400:449");
  parseWakeUp("5/15", "wake-up", cfg);
  const RevisitExperiment e = evaluateRevisits(*source, cfg, tmp.path());
  EXPECT_EQ(e.queries.size(), 20u);  // 400:404, 415:419, 430:434, 445:449
  const RevisitResult& r = e.results.at(0);
  ASSERT_EQ(r.wake_ups.size(), 4u);
  size_t localized = 0;
  for (const WakeUp& w : r.wake_ups) {
    EXPECT_EQ(w.frames.last, w.frames.first + 4);
    EXPECT_LE(w.localized, 5u);
    localized += w.revisit && w.localized > 0;
  }
  EXPECT_GE(localized, 2u);
  EXPECT_EQ(r.wrong, 0u);
  for (const RevisitLocalization& l : r.localizations) {
    const bool in_a_wake_up = (l.frame - 400) % 15 < 5;
    EXPECT_TRUE(in_a_wake_up) << "frame " << l.frame << " was never queried";
  }
  EXPECT_NE(revisitTable(e).find("localized by frame 5"), std::string::npos) << revisitTable(e);
  // Scan Context queries every frame of each wake-up on its own: it needs no local map.
  const RevisitResult& sc = e.results.at(1);
  ASSERT_EQ(sc.config, kScanContextName);
  ASSERT_EQ(sc.wake_ups.size(), 4u);
  size_t sc_localized = 0;
  for (const WakeUp& w : sc.wake_ups) {
    EXPECT_FALSE(w.wrong_first) << "frame " << w.frames.first;
    sc_localized += w.revisit && w.localized > 0;
  }
  EXPECT_GE(sc_localized, 1u);
  for (const RevisitLocalization& l : sc.localizations)
    EXPECT_LT((l.frame - 400) % 15, 5u) << "frame " << l.frame << " was never queried";
  EXPECT_NE(revisitTable(e).find("| scan-context | Scan Context (whole scan) |"), std::string::npos)
      << revisitTable(e);
  writeRevisitFiles(e, tmp.path());
  const YAML::Node j = YAML::LoadFile((tmp.path() / "revisits.json").string());
  EXPECT_EQ(j["results"][0]["wake_ups"].size(), 4u);
  EXPECT_EQ(j["results"][1]["wake_ups"].size(), 4u);
}

const std::filesystem::path kKittiSparse =
    std::filesystem::path(SEMSEGMAP_SHARED_DATA) / "kitti_odometry_00_sparse";

#define SEMSEGMAP_SKIP_WITHOUT_KITTI_SPARSE()                       \
  if (!std::filesystem::exists(kKittiSparse / "poses.txt"))         \
  GTEST_SKIP() << "no real KITTI sample (" << kKittiSparse.string() \
               << "): ../shared/data is not beside this checkout"

// Map from the 24 KITTI scans up to frame 276, localize the 12 of 1503-1759, ground truth checked.
RevisitExperimentConfig kittiRevisit() {
  RevisitExperimentConfig cfg;
  cfg.map_frames = parseFrameRanges("0:23", "map");
  cfg.query_frames = parseFrameRanges("24:35", "query");
  cfg.check_ground_truth = true;
  return cfg;
}

// The shipped configuration with one thing changed, under another name.
template <typename Change>
NamedConfig variant(NamedConfig config, const std::string& name, Change change) {
  config.name = name;
  change(config.config);
  return config;
}

// The first frames of the wake-ups at a revisit localized by their first scan; none may be
// wrong first.
std::vector<size_t> fromOneScan(const RevisitResult& r) {
  std::vector<size_t> frames;
  for (const WakeUp& w : r.wake_ups) {
    EXPECT_FALSE(w.wrong_first) << r.config << " frame " << w.frames.first;
    if (w.revisit && w.localized == 1) frames.push_back(w.frames.first);
  }
  return frames;
}

// The real KITTI 00 scans: map from the 24 scans up to frame 276, localize the 12 of 1503-1759,
// three of which (1576, 1615, 1634) pass within 1.5 m of mapped scans. The scans lie 10-40 m
// apart: 1576 localizes only from its own segments (localization.latest_scan_fallback_m), as its
// local map also holds 1511's and 1538's.
TEST(RevisitExperiment, RealKittiRevisitsAreFoundAndNoneIsFarOff) {
  SEMSEGMAP_SKIP_WITHOUT_KITTI_SPARSE();
  SEMSEGMAP_SKIP_WITHOUT_TORCH();
  TempDir tmp;
  auto source = openDataset("semantickitti:" + kKittiSparse.string());
  ASSERT_EQ(source->size(), 36u);
  RevisitExperimentConfig cfg = kittiRevisit();
  // The segments' own paths: relocalization off (its test is RealKittiWakeUpsAreAll...).
  NamedConfig shipped =
      variant(loadNamedConfig(kSource + "/config/lidar-camera.yaml"), "lidar-camera",
              [](PipelineConfig& c) { c.localization.relocalization.enabled = false; });
  ASSERT_GT(shipped.config.localization.latest_scan_fallback_m, 0.0);
  cfg.configs = {shipped, variant(shipped, "local-map-only", [](PipelineConfig& c) {
                   c.localization.latest_scan_fallback_m = 0.0;
                 })};
  const RevisitExperiment e = evaluateRevisits(*source, cfg, tmp.path());
  EXPECT_EQ(e.revisits, 3u);
  const RevisitResult& r = e.results.at(0);
  // 1576, 1615, 1634 and 1658 (query frames 27-30), the four.
  std::vector<size_t> localized;
  for (const RevisitLocalization& l : r.localizations) localized.push_back(l.frame);
  EXPECT_EQ(localized, (std::vector<size_t>{27, 28, 29, 30}));
  for (const RevisitLocalization& l : e.results.at(1).localizations)
    EXPECT_NE(l.frame, 27u) << "1576 localized from its local map";
  std::printf(
      "KITTI revisits: %zu localizations, %zu of %zu revisits within 1 m; %zu of %zu "
      "within 0.3 m of the registered ground truth (mean %.2f m); registration moved "
      "the ground truth by %.2f m on average\n",
      r.localizations.size(), r.revisits_localized, e.revisits, r.registered_below_0_3m,
      r.registered_compared, r.mean_registered_error_m, e.mean_correction_m);
  EXPECT_GE(r.revisits_localized, 2u);
  for (const RevisitLocalization& l : r.localizations)
    EXPECT_LT(l.translation_error_m, 2.0) << "frame " << l.frame;
  // KITTI's poses.txt puts the second pass about 0.8 m above the first: the scans registered to
  // the mapped ones move that far, and the localizations agree with the map's geometry.
  EXPECT_GE(e.registered, 3u);
  EXPECT_GT(e.mean_correction_m, 0.5);
  // Refined on the map's segment points, every localization is within 0.3 m and 1 degree.
  EXPECT_EQ(r.registered_compared, 4u);
  for (const RevisitLocalization& l : r.localizations) {
    if (l.registered_error_m >= 0) {
      EXPECT_LT(l.registered_error_m, 0.3) << "frame " << l.frame;
      EXPECT_LT(l.registered_rotation_error_deg, 1.0) << "frame " << l.frame;
    }
  }
  EXPECT_EQ(r.registered_below_0_3m, r.registered_compared) << "within 0.3 m and 1 degree";
  // The input has neither colour nor classes: the run takes the configuration's LiDAR-only
  // model (the S1 model, which sees grey points best) and says so.
  EXPECT_NE(r.model_note.find("no colour and no classes"), std::string::npos) << r.model_note;
  EXPECT_NE(r.model_note.find("model_lidar_only"), std::string::npos) << r.model_note;
  EXPECT_EQ(std::filesystem::path(r.model).filename(), "semsegmap-net.model") << r.model;

  // Scan Context on the same scans: the three revisit scans (1576, 1615 and 1634) score 0.08-0.11
  // to a mapped scan within 1.5 m, the others 0.29 or more to a wrong one, above its threshold:
  // it localizes the three, none wrongly. Its registration to the mapped scans near the match
  // lands where the ground-truth check's from the recorded pose lands (the same ICP to the same
  // scans), so against the registered ground truth it is exact by construction; against
  // poses.txt it is the second pass's 0.8 m off.
  const RevisitResult& sc = e.results.at(2);
  ASSERT_EQ(sc.config, kScanContextName);
  std::vector<size_t> by_scan_context;
  for (const RevisitLocalization& l : sc.localizations) {
    by_scan_context.push_back(l.frame);
    EXPECT_LT(l.translation_error_m, 1.1) << "frame " << l.frame;
    ASSERT_GE(l.registered_error_m, 0) << "frame " << l.frame << " registered";
    EXPECT_LT(l.registered_error_m, 0.3) << "frame " << l.frame;
    EXPECT_LT(l.registered_rotation_error_deg, 1.0) << "frame " << l.frame;
  }
  EXPECT_EQ(by_scan_context, (std::vector<size_t>{27, 28, 29}));
  EXPECT_EQ(sc.wrong, 0u);
  std::printf(
      "KITTI revisits by Scan Context: %zu localizations, %zu of %zu revisits within 1 m, "
      "%.1f ms a query (segments: %.1f ms)\n",
      sc.localizations.size(), sc.revisits_localized, e.revisits, sc.ms_per_query.value_or(-1),
      r.ms_per_query.value_or(-1));
}

// Woken up with an empty local map at each revisit, from the sparse scans 10-20 m apart. The map
// of the shipped configuration keeps the segments' earlier observations too: 1576 and 1634
// localize from their one scan, where the final observations alone (grown by the scans after the
// mapped one near them) let fewer. Judged against the registered ground truth: the refined poses
// agree with the map, and poses.txt puts the second pass about 0.8 m too high.
TEST(RevisitExperiment, RealKittiWakeUpLocalizesFromOneScanWithEarlierObservations) {
  SEMSEGMAP_SKIP_WITHOUT_KITTI_SPARSE();
  SEMSEGMAP_SKIP_WITHOUT_TORCH();
  TempDir tmp;
  auto source = openDataset("semantickitti:" + kKittiSparse.string());
  RevisitExperimentConfig cfg = kittiRevisit();
  parseWakeUp("1", "wake-up", cfg);
  // The local map's own segments: relocalization off (its test is the next one).
  NamedConfig shipped =
      variant(loadNamedConfig(kSource + "/config/lidar-camera.yaml"), "lidar-camera",
              [](PipelineConfig& c) { c.localization.relocalization.enabled = false; });
  ASSERT_GT(shipped.config.target_map.earlier_observations_apart_m, 0.0);
  cfg.configs = {shipped, variant(shipped, "final-only", [](PipelineConfig& c) {
                   c.target_map.earlier_observations_apart_m = 0.0;
                 })};
  const RevisitExperiment e = evaluateRevisits(*source, cfg, tmp.path());
  ASSERT_EQ(e.results.size(), 3u) << "the two configurations and Scan Context";
  const RevisitResult& with = e.results[0];
  const RevisitResult& without = e.results[1];
  EXPECT_GT(with.map_segments, without.map_segments);
  EXPECT_EQ(fromOneScan(with), (std::vector<size_t>{27, 29})) << "1576 and 1634";
  EXPECT_LT(fromOneScan(without).size(), 2u);
  for (const RevisitLocalization& l : with.localizations) {
    ASSERT_GE(l.registered_error_m, 0) << "frame " << l.frame << " registered";
    EXPECT_LT(l.registered_error_m, 0.3) << "frame " << l.frame;
    EXPECT_LT(l.registered_rotation_error_deg, 1.0) << "frame " << l.frame;
  }
  // Scan Context needs one scan by its nature: every revisit from its first.
  EXPECT_EQ(fromOneScan(e.results[2]), (std::vector<size_t>{27, 28, 29}));
}

// The real target: every query scan within 10 m of a mapped scan is localized from its one scan,
// and none of all the wake-ups wrongly, by the shipped configuration as it is (relocalization on,
// the map with 512 points a segment and a scan context a metre apart). 1615's places, voted for
// and proposed by its scan context 0.95 m off, are dragged 3.9 m onto a neighbouring wall by the
// check's 3 m correspondences: only the coarse pass retried at 2 m
// (check.retry_coarse_distance_m) finds it, 47 % of its points on the map's, which its scan
// context, distinct from every other place's (0.08 against 0.40), lets pass.
TEST(RevisitExperiment, RealKittiWakeUpsAreAllRelocalizedFromTheirOneScan) {
  SEMSEGMAP_SKIP_WITHOUT_KITTI_SPARSE();
  SEMSEGMAP_SKIP_WITHOUT_TORCH();
  TempDir tmp;
  auto source = openDataset("semantickitti:" + kKittiSparse.string());
  RevisitExperimentConfig cfg = kittiRevisit();
  parseWakeUp("1", "wake-up", cfg);
  cfg.scan_context = std::nullopt;
  const NamedConfig relocalize = loadNamedConfig(kSource + "/config/lidar-camera.yaml");
  ASSERT_TRUE(relocalize.config.localization.relocalization.enabled);
  cfg.configs = {relocalize, variant(relocalize, "no-retry", [](PipelineConfig& c) {
                   c.localization.relocalization.check.retry_coarse_distance_m = 0.0;
                 })};
  const RevisitExperiment e = evaluateRevisits(*source, cfg, tmp.path());
  ASSERT_EQ(e.results.size(), 2u);
  EXPECT_EQ(fromOneScan(e.results[0]), (std::vector<size_t>{27, 28, 29})) << "1576, 1615, 1634";
  EXPECT_EQ(e.results[0].wrong, 0u);
  // Within 0.3 m of the registered ground truth, and 2 degrees: 1576's reference is itself
  // ambiguous by 1.6 degrees (registered to mapped scan 95 alone or to 120 or 129 alone,
  // docs/real-data.md), and its one-scan pose lands 1.5 degrees from the reference.
  for (const RevisitLocalization& l : e.results[0].localizations) {
    ASSERT_GE(l.registered_error_m, 0) << "frame " << l.frame << " registered";
    EXPECT_LT(l.registered_error_m, 0.3) << "frame " << l.frame;
    EXPECT_LT(l.registered_rotation_error_deg, 2.0) << "frame " << l.frame;
  }
  EXPECT_LT(fromOneScan(e.results[1]).size(), 3u) << "1615 wants the retry";
  // The scan-context proposal of 1615 registers short of min_fitness: without the distinct scan
  // context, nothing else corroborates it (a proposal never confirms itself).
  cfg.configs = {variant(relocalize, "not-distinct", [](PipelineConfig& c) {
    c.localization.relocalization.scan_context_distinct_ratio = 0.0;
  })};
  std::filesystem::create_directories(tmp.path() / "strict");
  const RevisitExperiment strict = evaluateRevisits(*source, cfg, tmp.path() / "strict");
  EXPECT_EQ(fromOneScan(strict.results.at(0)), (std::vector<size_t>{27, 29}));
  EXPECT_EQ(strict.results.at(0).wrong, 0u);
}

// What a robot switched on with the shipped real-data configuration gets, with no edit: the map
// `map` writes with it carries what relocalization needs, and a wake-up at a revisit of the tiny
// world is localized from its one scan (7 of the 10 at 400-449, every 5th frame, when this was
// written), none wrongly, every pose through the registration check of a lost robot.
TEST(RevisitExperiment, TheShippedRealDataConfigurationRelocalizesTinyWorldWakeUpsAsItIs) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  SEMSEGMAP_SKIP_WITHOUT_TORCH();
  TempDir tmp;
  auto source = openDataset("sim:world=1,run=S1,preset=tiny");
  RevisitExperimentConfig cfg = tinyRevisit("400:449");
  cfg.configs = {loadNamedConfig(kSource + "/config/lidar-camera.yaml")};
  ASSERT_TRUE(cfg.configs[0].config.localization.relocalization.enabled);
  parseWakeUp("1/5", "wake-up", cfg);
  cfg.scan_context.reset();
  const RevisitExperiment e = evaluateRevisits(*source, cfg, tmp.path());
  ASSERT_EQ(e.results.size(), 1u);
  const RevisitResult& r = e.results[0];
  ASSERT_EQ(r.wake_ups.size(), 10u);
  EXPECT_GE(fromOneScan(r).size(), 5u) << revisitTable(e);
  EXPECT_EQ(r.wrong, 0u);
  EXPECT_EQ(r.ambiguous, 0u);
  // Each wake-up is one scan of a lost robot: every pose passed the registration check, whose
  // fitness localizations.csv gives, and the whole-map search found most.
  std::istringstream csv(readFileBytes(tmp.path() / "lidar-camera" / "localizations.csv"));
  const auto fields = [](const std::string& line) {
    std::vector<std::string> out;
    std::istringstream in(line);
    for (std::string f; std::getline(in, f, ',');) out.push_back(f);
    return out;
  };
  std::string line;
  std::getline(csv, line);
  const std::vector<std::string> header = fields(line);
  const auto column = [&](const std::string& name) {
    return static_cast<size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  const size_t path = column("path"), fitness = column("fitness");
  ASSERT_LT(std::max(path, fitness), header.size()) << line;
  size_t rows = 0, relocalized = 0;
  while (std::getline(csv, line)) {
    const std::vector<std::string> row = fields(line);
    ASSERT_EQ(row.size(), header.size()) << line;
    ++rows;
    relocalized += row[path] == "relocalization" || row[path] == "scan-context";
    EXPECT_FALSE(row[fitness].empty()) << "a pose without its registration check: " << line;
  }
  EXPECT_EQ(rows, r.localizations.size());
  EXPECT_GE(relocalized, 5u);
}

}  // namespace
}  // namespace semsegmap
