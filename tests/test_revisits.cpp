// The revisit experiment (eval/revisit_experiment.h): frame ranges, the checks made before any
// frame is read, and the experiment end to end on a simulated run that drives through the same
// street again and on the real KITTI revisits.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>

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
  cfg.configs = {loadNamedConfig(kSource + "/config/semsegmap-kitti.yaml")};
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
}

void expectPng(const std::filesystem::path& path) {
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
  EXPECT_EQ(readFileBytes(path).substr(1, 3), "PNG") << path;
}

// S1 of the tiny world drives the street of its first 60 frames again from frame 395 on.
TEST(RevisitExperiment, LocalizesTheRevisitsOfASimulatedRun) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  SEMSEGMAP_SKIP_WITHOUT_TORCH();
  TempDir tmp;
  auto source = openDataset("sim:world=1,run=S1,preset=tiny");
  RevisitExperimentConfig cfg;
  cfg.map_frames = parseFrameRanges("0:59", "map");
  cfg.query_frames = parseFrameRanges("395:460", "query");
  cfg.configs = {loadNamedConfig(kSource + "/config/semsegmap.yaml")};
  const RevisitExperiment e = evaluateRevisits(*source, cfg, tmp.path());
  writeRevisitFiles(e, tmp.path());
  ASSERT_EQ(e.queries.size(), 66u);
  EXPECT_EQ(e.queries.front().frame, 395u);
  EXPECT_GT(e.revisits, 40u);
  ASSERT_EQ(e.results.size(), 1u);
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
  EXPECT_NE(revisitTable(e).find("| semsegmap |"), std::string::npos);
}

// The real KITTI 00 scans: map from the 24 scans up to frame 276, localize the 12 of 1503-1759,
// three of which (1576, 1615, 1634) pass within 1.5 m of mapped scans.
TEST(RevisitExperiment, RealKittiRevisitsAreFoundAndNoneIsFarOff) {
  const std::filesystem::path sparse =
      std::filesystem::path(SEMSEGMAP_SHARED_DATA) / "kitti_odometry_00_sparse";
  if (!std::filesystem::exists(sparse / "poses.txt"))
    GTEST_SKIP() << "no real KITTI sample (" << sparse.string()
                 << "): ../shared/data is not beside this checkout";
  SEMSEGMAP_SKIP_WITHOUT_TORCH();
  TempDir tmp;
  auto source = openDataset("semantickitti:" + sparse.string());
  ASSERT_EQ(source->size(), 36u);
  RevisitExperimentConfig cfg;
  cfg.map_frames = parseFrameRanges("0:23", "map");
  cfg.query_frames = parseFrameRanges("24:35", "query");
  cfg.configs = {loadNamedConfig(kSource + "/config/semsegmap-kitti.yaml")};
  const RevisitExperiment e = evaluateRevisits(*source, cfg, tmp.path());
  EXPECT_EQ(e.revisits, 3u);
  const RevisitResult& r = e.results.at(0);
  std::printf("KITTI revisits: %zu localizations, %zu of %zu revisits within 1 m\n",
              r.localizations.size(), r.revisits_localized, e.revisits);
  EXPECT_GE(r.revisits_localized, 2u);
  for (const RevisitLocalization& l : r.localizations)
    EXPECT_LT(l.translation_error_m, 2.0) << "frame " << l.frame;
}

}  // namespace
}  // namespace semsegmap
