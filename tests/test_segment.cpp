#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>

#include "semsegmap/segment/completeness.h"
#include "semsegmap/segment/incremental_segmenter.h"
#include "semsegmap/settings/config.h"

using namespace semsegmap;

namespace {

EnrichedPoint point(const Eigen::Vector3f& p, ClassId c = cls::kBuilding, float hue = 0.3f) {
  EnrichedPoint q;
  q.x = p.x();
  q.y = p.y();
  q.z = p.z();
  q.h = hue;
  q.s = q.v = 0.5f;
  q.has_color = true;
  q.has_class = true;
  q.class_id = c;
  return q;
}

// A flat patch of points 0.1 m apart in y-z at a given x, one point per voxel (each at the
// centre of its voxel, so voxel centroids are exactly these points).
EnrichedCloud wall(float x, int ny, int nz, ClassId c, float hue, float y0 = 0.0f) {
  EnrichedCloud out;
  for (int j = 0; j < ny; ++j)
    for (int k = 0; k < nz; ++k)
      out.push_back(point({x, y0 + 0.05f + 0.1f * j, 1.05f + 0.1f * k}, c, hue));
  return out;
}

struct SegRun {
  LocalMap map;
  IncrementalSegmenter seg;
  size_t frame = 0;
  explicit SegRun(const SegmentationConfig& c, LocalMapConfig lm = {})
      : map(lm, ClassTable::Default()), seg(c) {}
  SegmentationUpdate add(const EnrichedCloud& cloud, Eigen::Vector2d robot = {0, 0}) {
    const LocalMapUpdate u = map.update(cloud, Pose::Identity(), robot);
    const size_t index = frame++;
    return seg.update(map, u, index, 0.2 * static_cast<double>(index));
  }
  // Partition of the active voxels as a set of voxel sets.
  std::set<std::set<VoxelKey>> partition() const {
    std::map<SegmentId, std::set<VoxelKey>> groups;
    for (const auto& [key, v] : map.voxels())
      if (v.active) groups[seg.segmentOf(key)].insert(key);
    std::set<std::set<VoxelKey>> out;
    for (auto& [id, g] : groups) out.insert(g);
    return out;
  }
};

SegmentationConfig semsegmapConfig() {
  SegmentationConfig c;
  c.min_segment_points = 1;
  return c;
}

}  // namespace

TEST(SemanticDistance, IsTheFormulaOfThePaper) {
  SegmentationConfig c;  // d 0.3, t_h 0.1, p_h 0.05, p_c 0.15
  const SemanticDistance d(c);
  DistanceVoxel a, b;
  a.position = {0, 0, 0};
  b.position = {0.1f, 0.2f, 0.0f};
  a.has_color = b.has_color = true;
  a.has_class = b.has_class = true;
  a.class_id = b.class_id = cls::kBuilding;
  a.hue = 0.95f;
  b.hue = 0.03f;  // cyclic difference 0.08 <= t_h: no hue penalty
  EXPECT_NEAR(d.squared(a, b), 0.05f, 1e-6f);
  b.hue = 0.1f;  // difference 0.15 > t_h
  EXPECT_NEAR(d.squared(a, b), 0.05f + 0.05f * 0.05f, 1e-6f);
  b.class_id = cls::kVegetation;
  EXPECT_NEAR(d.squared(a, b), 0.05f + 0.0025f + 0.0225f, 1e-6f);
  // An unobserved voxel's class id means nothing: no penalty.
  b.has_class = false;
  EXPECT_NEAR(d.squared(a, b), 0.05f + 0.0025f, 1e-6f);
  b.has_class = true;
  // Without colour or class evidence there is nothing to penalise.
  b.has_color = false;
  b.class_id = cls::kUnknown;
  EXPECT_NEAR(d.squared(a, b), 0.05f, 1e-6f);
  EXPECT_NEAR(hueDifference(0.9f, 0.1f), 0.2f, 1e-6f);
}

TEST(IncrementalSegmenter, PenaltiesAreSoftConstraintsExactlyAsTheFormulaSays) {
  SegmentationConfig on =
      semsegmapConfig();  // d_segment 0.3, p_c 0.15: split when gap^2 + p_c^2 > d^2
  SegmentationConfig off = on;
  off.hue_penalty = off.class_penalty = 0.0;
  // Two touching surfaces of different class 0.28 m apart: 0.28^2 + 0.15^2 > 0.3^2.
  for (const auto& [gap, joined_with_penalties] :
       std::vector<std::pair<float, bool>>{{0.28f, false}, {0.25f, true}}) {
    EnrichedCloud scene = wall(1.05f, 10, 10, cls::kBuilding, 0.3f);
    const EnrichedCloud other = wall(1.05f + gap, 10, 10, cls::kFence, 0.3f);
    scene.insert(scene.end(), other.begin(), other.end());
    SegRun with(on), without(off);
    with.add(scene);
    without.add(scene);
    EXPECT_EQ(without.partition().size(), 1u) << "gap " << gap;
    EXPECT_EQ(with.partition().size(), joined_with_penalties ? 1u : 2u) << "gap " << gap;
  }
  // The hue penalty alone (0.05) is too small to split at 0.28 m: 0.28^2 + 0.05^2 < 0.3^2.
  EnrichedCloud scene = wall(1.05f, 10, 10, cls::kBuilding, 0.1f);
  const EnrichedCloud blue = wall(1.33f, 10, 10, cls::kBuilding, 0.6f);
  scene.insert(scene.end(), blue.begin(), blue.end());
  SegRun hue_only(on);
  hue_only.add(scene);
  EXPECT_EQ(hue_only.partition().size(), 1u);
}

TEST(IncrementalSegmenter, MergeKeepsTheOldestIdAndIsRecorded) {
  SegRun run(semsegmapConfig());
  run.add(wall(1.05f, 5, 5, cls::kBuilding, 0.3f, 0.0f));  // id 0
  run.add(wall(1.05f, 5, 5, cls::kBuilding, 0.3f, 2.0f));  // id 1, 1.5 m away
  ASSERT_EQ(run.partition().size(), 2u);
  const auto first = run.seg.segmentOf(packVoxelKey(run.map.voxelIndex({1.05f, 0.05f, 1.05f})));
  const auto second = run.seg.segmentOf(packVoxelKey(run.map.voxelIndex({1.05f, 2.05f, 1.05f})));
  EXPECT_LT(first, second);
  // A bridge between them joins both into one segment that keeps the older id.
  const SegmentationUpdate u = run.add(wall(1.05f, 16, 5, cls::kBuilding, 0.3f, 0.4f));
  ASSERT_EQ(run.partition().size(), 1u);
  ASSERT_EQ(u.merges.size(), 1u);
  EXPECT_EQ(u.merges[0].survivor, first);
  EXPECT_EQ(u.merges[0].absorbed, second);
  EXPECT_EQ(run.seg.segmentOf(packVoxelKey(run.map.voxelIndex({1.05f, 2.05f, 1.05f}))), first);
}

TEST(IncrementalSegmenter, IncrementalEqualsBatchOnRandomScenes) {
  // Property: revealing the voxels over several steps gives the same partition as segmenting
  // all of them at once (the distance is symmetric and each pair is tested when the later of
  // the two becomes active).
  std::mt19937 rng(42);
  for (int scene = 0; scene < 20; ++scene) {
    std::uniform_real_distribution<float> pos(0.0f, 3.0f);
    std::uniform_int_distribution<int> cls_pick(4, 8);
    std::uniform_real_distribution<float> hue(0.0f, 1.0f);
    // Blobs of points on a 0.1 m lattice, each blob with a class and hue, some noisy.
    std::map<VoxelKey, EnrichedPoint> unique;
    for (int blob = 0; blob < 8; ++blob) {
      const Eigen::Vector3f c(pos(rng), pos(rng), pos(rng) + 1.0f);
      const ClassId k = static_cast<ClassId>(cls_pick(rng));
      const float h = hue(rng);
      std::uniform_int_distribution<int> off(-4, 4);
      for (int n = 0; n < 120; ++n) {
        const Eigen::Vector3i idx =
            (c * 10.0f).cast<int>() + Eigen::Vector3i(off(rng), off(rng), off(rng));
        const Eigen::Vector3f p = (idx.cast<float>() + Eigen::Vector3f::Constant(0.5f)) * 0.1f;
        const bool noisy = rng() % 10 == 0;
        unique[packVoxelKey(idx)] =
            point(p, noisy ? static_cast<ClassId>(cls_pick(rng)) : k, noisy ? hue(rng) : h);
      }
    }
    EnrichedCloud all;
    for (const auto& [key, p] : unique) all.push_back(p);
    std::shuffle(all.begin(), all.end(), rng);

    SegRun batch(semsegmapConfig());
    batch.add(all);
    SegRun incremental(semsegmapConfig());
    const size_t steps = 2 + rng() % 6;
    for (size_t s = 0; s < steps; ++s)
      incremental.add(EnrichedCloud(all.begin() + s * all.size() / steps,
                                    all.begin() + (s + 1) * all.size() / steps));
    EXPECT_EQ(incremental.partition(), batch.partition()) << "scene " << scene;
    EXPECT_GT(batch.partition().size(), 1u);
  }
}

TEST(IncrementalSegmenter, ObservationsSizesAndFinishing) {
  SegmentationConfig c;
  c.min_segment_points = 20;
  c.max_segment_points = 400;
  SegRun run(c);
  // 16 voxels: below the minimum, not reported.
  run.add(wall(10.05f, 4, 4, cls::kBuilding, 0.3f));
  EXPECT_TRUE(run.seg.activeSegments().empty());
  // 25 voxels: reported, first observation.
  run.add(wall(10.05f, 5, 5, cls::kBuilding, 0.3f));
  ASSERT_EQ(run.seg.activeSegments().size(), 1u);
  EXPECT_EQ(run.seg.activeSegments()[0]->observations.size(), 1u);
  // 26 voxels: grew by 4 %, no new observation; 30 (20 % more than 25) gives one.
  run.add(wall(10.05f, 1, 1, cls::kBuilding, 0.3f, 0.5f));
  EXPECT_EQ(run.seg.activeSegments()[0]->observations.size(), 1u);
  const auto u = run.add(wall(10.05f, 6, 5, cls::kBuilding, 0.3f));
  ASSERT_EQ(u.observed.size(), 1u);
  const Segment* s = run.seg.activeSegments()[0];
  ASSERT_EQ(s->observations.size(), 2u);
  EXPECT_EQ(s->observations[1].n_points, 30u);
  EXPECT_NEAR(s->completeness(0), 25.0 / 30.0, 1e-9);
  EXPECT_NEAR(s->completeness(1), 1.0, 1e-9);
  EXPECT_EQ(s->observations[1].majority_class, cls::kBuilding);
  // Older observations keep their numbers but not their points (memory stays bounded).
  EXPECT_TRUE(s->observations[0].points.empty());
  EXPECT_EQ(s->observations[1].points.size(), 30u);

  // A segment that grows past the maximum is dropped and never reported again.
  run.add(wall(20.05f, 25, 20, cls::kVegetation, 0.3f));
  EXPECT_EQ(run.seg.activeSegments().size(), 1u);

  // The robot drives away: the wall's voxels leave, and it comes out as finished.
  const auto gone = run.add({}, {200.0, 0.0});
  ASSERT_EQ(gone.finished.size(), 1u);
  EXPECT_EQ(gone.finished[0].last().n_points, 30u);
  EXPECT_TRUE(run.seg.activeSegments().empty());
}

// A reported segment that grows past the maximum is said dropped once, so that whoever kept it
// (the local segments a localization queries) lets it go; so is one that absorbs a dropped one.
TEST(IncrementalSegmenter, AReportedSegmentThatBecomesTooLargeIsReportedDroppedOnce) {
  SegmentationConfig c;
  c.min_segment_points = 20;
  c.max_segment_points = 400;
  SegRun run(c);
  const auto first = run.add(wall(10.05f, 10, 10, cls::kBuilding, 0.3f));
  ASSERT_EQ(first.observed.size(), 1u);
  const SegmentId grown = first.observed[0];
  EXPECT_TRUE(first.dropped.empty());
  const auto past = run.add(wall(10.05f, 25, 20, cls::kBuilding, 0.3f));
  EXPECT_EQ(past.dropped, std::vector<SegmentId>{grown});
  EXPECT_TRUE(past.observed.empty());
  EXPECT_TRUE(run.seg.activeSegments().empty());
  EXPECT_TRUE(run.add(wall(10.05f, 30, 20, cls::kBuilding, 0.3f)).dropped.empty()) << "once";

  // A reported segment absorbs one that was too large from its first step (never reported):
  // the oldest id survives, dropped, and is said so.
  const auto small = run.add(wall(30.05f, 5, 5, cls::kVegetation, 0.6f, -1.0f));
  ASSERT_EQ(small.observed.size(), 1u);
  const SegmentId older = small.observed[0];
  EXPECT_TRUE(run.add(wall(30.05f, 25, 20, cls::kVegetation, 0.6f)).dropped.empty());
  const auto bridged = run.add(wall(30.05f, 5, 5, cls::kVegetation, 0.6f, -0.5f));
  ASSERT_EQ(bridged.merges.size(), 1u);
  EXPECT_EQ(bridged.merges[0].survivor, older);
  EXPECT_EQ(bridged.dropped, std::vector<SegmentId>{older});
}

TEST(PipelineConfig, ShippedConfigsParse) {
  const PipelineConfig sem =
      loadPipelineConfig(std::string(SEMSEGMAP_SOURCE_DIR) + "/config/semsegmap.yaml");
  EXPECT_DOUBLE_EQ(sem.segmentation.d_segment_m, 0.3);
  EXPECT_DOUBLE_EQ(sem.segmentation.hue_threshold, 0.1);
  EXPECT_DOUBLE_EQ(sem.segmentation.hue_penalty, 0.05);
  EXPECT_DOUBLE_EQ(sem.segmentation.class_penalty, 0.15);
  const PipelineConfig geo =
      loadPipelineConfig(std::string(SEMSEGMAP_SOURCE_DIR) + "/config/segmap.yaml");
  EXPECT_DOUBLE_EQ(geo.segmentation.d_segment_m, 0.2);
  EXPECT_DOUBLE_EQ(geo.segmentation.hue_penalty, 0.0);
  EXPECT_DOUBLE_EQ(geo.segmentation.class_penalty, 0.0);
  EXPECT_DOUBLE_EQ(geo.local_map.voxel_size_m, 0.1);
}

TEST(PipelineConfig, UnknownKeysAndBadValuesNameTheFile) {
  const auto path = std::filesystem::temp_directory_path() / "semsegmap_test_config.yaml";
  auto expectError = [&](const std::string& yaml, const std::string& fragment) {
    std::ofstream(path) << yaml;
    try {
      loadPipelineConfig(path);
      ADD_FAILURE() << "expected an error for: " << yaml;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expectError("segmentation:\n  d_segmnt_m: 0.3\n", "segmentation.d_segmnt_m");
  expectError("segmentaton:\n  d_segment_m: 0.3\n", "segmentaton");
  expectError("segmentation:\n  d_segment_m: fast\n", "segmentation.d_segment_m");
  expectError("segmentation:\n  d_segment_m: -1\n", "d_segment_m");
  expectError("local_map: [1, 2]\n", "local_map");
  expectError("localization:\n  refinement:\n    neighbours_m: -3\n",
              "localization.refinement.neighbours_m");
  expectError("refinement:\n  neighbours_m: -3\n", "refinement.neighbours_m");  // an old key
  expectError("localization:\n  latest_scan_fallback_m: -5\n",
              "localization.latest_scan_fallback_m");
  expectError("descriptor:\n  kind: semsegmap-net\n  keypoints: 16\n",
              "descriptor.keypoints: only for 3dsmoothnet");
  std::filesystem::remove(path);
  EXPECT_THROW(loadPipelineConfig("/nonexistent/config.yaml"), std::runtime_error);
}

// issue 18: a directory given as config said "basic_filebuf::underflow", `localization.k:
// 1000000000` (now localization.localizer.index.k) "std::bad_alloc" and a value of the wrong type
// yaml-cpp's "bad conversion". Each now names the file, the key and the value, and every count has
// limits.
TEST(PipelineConfig, CountsValuesAndDirectoriesNameTheFileAndTheKey) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("semsegmap_test_config_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "config.yaml");  // a directory of that name
  const auto errorOf = [](const std::filesystem::path& path) {
    try {
      loadPipelineConfig(path);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(errorOf(dir / "config.yaml"),
            (dir / "config.yaml").string() + ": not a config file (a directory or a device)");
  const auto path = dir / "file.yaml";
  const auto expectError = [&](const std::string& yaml, const std::string& what) {
    std::ofstream(path) << yaml;
    EXPECT_EQ(errorOf(path), path.string() + ": " + what) << yaml;
  };
  expectError("localization:\n  localizer:\n    index:\n      k: 1000000000\n",
              "localization.localizer.index.k: wrong type: expected an integer in [1, 1000], got "
              "'1000000000'");
  // An old key is named as the file has it.
  expectError("localization:\n  k: 2.5\n",
              "localization.k: wrong type: expected an integer in [1, 1000], got '2.5'");
  expectError("segmentation:\n  d_segment_m: .inf\n",
              "segmentation.d_segment_m: wrong type: expected a finite number, got '.inf'");
  expectError("descriptor:\n  batch: [1]\n",
              "descriptor.batch: wrong type: expected an integer in [1, 4096], got a list");
  expectError("local_map:\n  remove_unknown_class: maybe\n",
              "local_map.remove_unknown_class: wrong type: expected true or false, got 'maybe'");
  expectError("semantics:\n  mean: [0.5, nan, 0.5]\n",
              "semantics.mean: wrong type: expected a list of finite numbers, got a list");
  expectError("odometry:\n  icp:\n    max_iterations: -5\n",
              "odometry.icp.max_iterations: wrong type: expected an integer in [1, 10000], got "
              "'-5'");
  expectError("? [a, b]\n: 1\n", "the top level: a key that is a list");
  std::filesystem::remove_all(dir);
}

TEST(CompletenessEstimate, ShareOfThePointsAWindowBeforeWithARunningMaximum) {
  // Frames 0, 2, 4: growing fast; 20: grown little since 10 frames before; 30: a spurt (merge).
  const std::vector<ObservationSize> obs = {{0, 100}, {2, 200}, {4, 400}, {20, 440}, {30, 880}};
  const std::vector<double> e = estimateCompleteness(obs, 10);
  ASSERT_EQ(e.size(), obs.size());
  EXPECT_DOUBLE_EQ(e[0], 0.0);  // nothing a window before the first observation
  EXPECT_DOUBLE_EQ(e[1], 0.0);
  EXPECT_DOUBLE_EQ(e[2], 0.0);
  EXPECT_DOUBLE_EQ(e[3], 400.0 / 440.0);  // frame 10's size is frame 4's observation
  EXPECT_DOUBLE_EQ(e[4], 400.0 / 440.0);  // 440/880 is less: the running maximum holds
  // The window decides what counts as before: with 2 frames, frame 2 sees frame 0's 100 points.
  const std::vector<double> short_window = estimateCompleteness(obs, 2);
  EXPECT_DOUBLE_EQ(short_window[1], 0.5);
  EXPECT_DOUBLE_EQ(short_window[2], 0.5);
  EXPECT_TRUE(estimateCompleteness({}, 10).empty());
}
