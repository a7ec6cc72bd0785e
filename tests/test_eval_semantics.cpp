// eval semantics (eval/semantics_experiment.h): camera classes on the LiDAR points against the
// per-point ground truth, on a tiny simulated world and on the real mini KITTI frames with a real
// Cityscapes network (skipped when ../shared is absent).
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "error_text.h"
#include "mini_kitti.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/eval/semantics_experiment.h"
#include "semsegmap/settings/config.h"
#include "temp_dir.h"

namespace semsegmap {
namespace {

namespace fs = std::filesystem;
using test_support::errorOf;
using test_support::TempDir;

TEST(SemanticScores, AccuracySharesAndIou) {
  SemanticScores s;
  s.add(cls::kRoad, true, cls::kRoad);
  s.add(cls::kRoad, true, cls::kSidewalk);
  s.add(cls::kSidewalk, true, cls::kSidewalk);
  s.add(cls::kCar, false, cls::kRoad);    // no camera saw it: counted, not classified
  s.add(cls::kUnknown, true, cls::kCar);  // no ground truth: not counted at all
  EXPECT_EQ(s.points, 4u);
  EXPECT_EQ(s.classified, 3u);
  EXPECT_EQ(s.correct, 2u);
  EXPECT_DOUBLE_EQ(s.accuracy(), 2.0 / 3);
  EXPECT_DOUBLE_EQ(s.classifiedShare(), 3.0 / 4);
  EXPECT_DOUBLE_EQ(s.correctShare(), 2.0 / 4);
  EXPECT_DOUBLE_EQ(s.iou(cls::kRoad), 1.0 / 2);      // TP 1, FN 1
  EXPECT_DOUBLE_EQ(s.iou(cls::kSidewalk), 1.0 / 2);  // TP 1, FP 1
  EXPECT_DOUBLE_EQ(s.iou(cls::kCar), -1.0);          // in neither
}

// Ids of a user's class table can be large (16 bits); merging adds pair by pair.
TEST(ConfusionMatrix, CountsPairsOfAnyIdAndMerges) {
  ConfusionMatrix a, b;
  a.add(259, 259, 3);
  a.add(259, 7);
  b.add(7, 7, 2);
  b.add(40000, 259);
  a += b;
  EXPECT_EQ(a.total(), 7u);
  EXPECT_EQ(a.correct(), 5u);
  EXPECT_EQ(a.truthCount(259), 4u);
  EXPECT_EQ(a.predictedCount(259), 4u);
  EXPECT_EQ(a.count(40000, 259), 1u);
  EXPECT_DOUBLE_EQ(a.iou(259), 3.0 / 5);  // TP 3, FN 1, FP 1
  EXPECT_DOUBLE_EQ(a.iou(7), 2.0 / 3);    // TP 2, FP 1
  EXPECT_DOUBLE_EQ(a.iou(40000), 0.0);    // truth, never predicted
  EXPECT_DOUBLE_EQ(a.iou(1), -1.0);
}

#if SEMSEGMAP_WITH_SIM
// The dataset's frames with every camera label image set to one class, or removed at one frame.
class RelabelledSource : public FrameSource {
 public:
  RelabelledSource(std::unique_ptr<FrameSource> inner, ClassId id, size_t unlabelled_frame)
      : inner_(std::move(inner)), id_(id), unlabelled_(unlabelled_frame) {}
  const DatasetInfo& info() const override { return inner_->info(); }
  size_t size() const override { return inner_->size(); }
  Frame frame(size_t index) override {
    Frame f = inner_->frame(index);
    for (CameraFrame& c : f.cameras)
      if (index == unlabelled_)
        c.label = Image();
      else
        std::fill(c.label.data.begin(), c.label.data.end(), static_cast<uint8_t>(id_));
    return f;
  }

 private:
  std::unique_ptr<FrameSource> inner_;
  ClassId id_;
  size_t unlabelled_;
};

SemanticsEvalConfig simConfig() {
  SemanticsEvalConfig c;
  c.pipeline = loadPipelineConfig(fs::path(SEMSEGMAP_SOURCE_DIR) / "config" / "semsegmap.yaml");
  return c;
}

TEST(EvalSemantics, TinyWorldCameraLabelsLandOnTheirPoints) {
  auto source = openDataset("sim:world=1,preset=tiny,frames=4");
  const SemanticsEvaluation e = evaluateSemantics(*source, simConfig());
  ASSERT_EQ(e.frames.size(), 4u);
  EXPECT_GT(e.per_frame.points, 10000u);
  // The simulator's label images are its ground truth rendered: only the projection, occlusion
  // and the camera/LiDAR parallax can make a point's class wrong.
  EXPECT_GT(e.per_frame.accuracy(), 0.9);
  EXPECT_GT(e.per_frame.classifiedShare(), 0.5);  // three cameras around the car
  // The votes keep what earlier frames saw; only the points beyond the local map's radius (50 m),
  // which no voxel holds, lose the class the camera gave them.
  EXPECT_GT(e.after_votes.classifiedShare(), e.per_frame.classifiedShare() - 0.02);
  EXPECT_GT(e.after_votes.accuracy(), 0.85);
  EXPECT_GT(e.per_frame.iou(cls::kRoad), 0.8);
  EXPECT_GT(e.segments, 0u);
  EXPECT_GT(e.segments_with_class, 0u);
  const nlohmann::ordered_json j = toJson(e);
  EXPECT_EQ(j["per_frame"]["points"], e.per_frame.points);
  EXPECT_EQ(j["per_frame_results"].size(), 4u);
  EXPECT_NE(semanticsTable(e).find("after votes"), std::string::npos);
}

TEST(EvalSemantics, NoisyLabelsScoreLower) {
  auto perfect = openDataset("sim:world=1,preset=tiny,frames=3");
  auto noisy = openDataset("sim:world=1,preset=tiny,frames=3,label_noise=3");
  const double a = evaluateSemantics(*perfect, simConfig()).per_frame.accuracy();
  const double b = evaluateSemantics(*noisy, simConfig()).per_frame.accuracy();
  EXPECT_LT(b, a - 0.02) << "perfect " << a << ", noisy " << b;
}

// The classes measured are the cameras' alone: with every label image saying building, every
// classified point is predicted building, whatever its point label says.
TEST(EvalSemantics, ClassesComeFromTheCamerasNotThePointLabels) {
  RelabelledSource source(openDataset("sim:world=1,preset=tiny,frames=2"), cls::kBuilding, 99);
  const SemanticsEvaluation e = evaluateSemantics(source, simConfig());
  ASSERT_GT(e.per_frame.classified, 1000u);
  EXPECT_EQ(e.per_frame.confusion.predictedCount(cls::kBuilding), e.per_frame.classified);
  EXPECT_LT(e.per_frame.accuracy(), 0.5);
}

// The shipped network on its budget: the first scan has no labels yet (it counts as not
// classified, instead of stopping the run), the others take earlier pictures' labels, carried by
// odometry; what lands on the points is near what each picture's own labels give.
TEST(EvalSemantics, ANetworkOnABudgetIsMeasuredScanByScan) {
  DatasetOptions options;
  options.semantics =
      loadSemanticsConfig(fs::path(SEMSEGMAP_SOURCE_DIR) / "config" / "semantics-sim-network.yaml");
  options.class_maps_dir = fs::path(SEMSEGMAP_SOURCE_DIR) / "config" / "class_maps";
  const std::string spec = "sim:world=1,preset=tiny,frames=4";
  auto budget = openDataset(spec, options);
  const SemanticsEvaluation b = evaluateSemantics(*budget, simConfig());
  ASSERT_EQ(b.frames.size(), 4u);
  options.semantics.budget_cores = options.semantics.latency_s = 0;  // every picture, its own
  auto every = openDataset(spec, options);
  const SemanticsEvaluation e = evaluateSemantics(*every, simConfig());
  EXPECT_LT(b.per_frame.classifiedShare(), e.per_frame.classifiedShare());
  EXPECT_GT(b.per_frame.classifiedShare(), 0.4);
  EXPECT_GT(b.per_frame.accuracy(), e.per_frame.accuracy() - 0.05);
}

// A stop request (Ctrl-C) between frames: the scores are those of the frames done, marked.
TEST(EvalSemantics, AStopRequestEndsItBetweenFrames) {
  auto source = openDataset("sim:world=1,preset=tiny,frames=4");
  std::atomic<bool> stop{false};
  SemanticsEvalConfig c = simConfig();
  c.stop = StopToken(stop);
  const SemanticsEvaluation e =
      evaluateSemantics(*source, c, [&](size_t done, size_t) { stop = done == 2; });
  EXPECT_TRUE(e.interrupted);
  ASSERT_EQ(e.frames.size(), 2u);
  EXPECT_TRUE(toJson(e)["interrupted"].get<bool>());
  EXPECT_EQ(toJson(e)["frames"].get<size_t>(), 2u);
}

TEST(EvalSemantics, RefusesWhatItCannotMeasureInOneLine) {
  RelabelledSource unlabelled(openDataset("sim:world=1,preset=tiny,frames=3"), cls::kRoad, 1);
  std::string msg = errorOf([&] { evaluateSemantics(unlabelled, simConfig()); });
  EXPECT_MENTIONS(msg, "frame 1 has no label image in any camera");
  EXPECT_ONE_LINE(msg);
  auto no_cameras = openDataset("sim:world=1,preset=tiny,frames=2,cameras=0");
  msg = errorOf([&] { evaluateSemantics(*no_cameras, simConfig()); });
  EXPECT_MENTIONS(msg, "has no camera");
  EXPECT_ONE_LINE(msg);
}
#endif

TEST(EvalSemantics, RealMiniKittiWithARealNetwork) {
  SEMSEGMAP_SKIP_WITHOUT_MINI_KITTI();
  if (!fs::exists(test_support::kEspNet))
    GTEST_SKIP() << "no ESPNetv2 network (" << test_support::kEspNet.string() << ")";
  TempDir tmp;
  const fs::path config =
      test_support::writeEspNetConfig(tmp.path(), fs::path(SEMSEGMAP_SOURCE_DIR) / "config");
  DatasetOptions options;
  options.semantics = loadSemanticsConfig(config);
  options.class_maps_dir = fs::path(SEMSEGMAP_SOURCE_DIR) / "config" / "class_maps";
  const fs::path sequence = test_support::miniKittiSequence(tmp.path(), "05");
  auto source = openDataset("semantickitti:" + sequence.string(), options);
  SemanticsEvalConfig c;
  c.pipeline = loadPipelineConfig(config);
  const SemanticsEvaluation e = evaluateSemantics(*source, c);
  ASSERT_EQ(e.frames.size(), 10u);
  // One front camera on a 360-degree LiDAR: about a sixth of the scan is in the picture (82 of
  // 360 degrees of azimuth, the upper 17 of the 27 degrees of rings), less what it cannot see.
  EXPECT_GT(e.per_frame.classifiedShare(), 0.12);
  EXPECT_LT(e.per_frame.classifiedShare(), 0.35);
  // A Cityscapes network on KITTI's pictures, through P2 and Tr: most points it classes are
  // right (a misplaced camera would put the road's class on cars and walls).
  EXPECT_GT(e.per_frame.accuracy(), 0.7);
  EXPECT_GT(e.per_frame.iou(cls::kRoad), 0.6);
  // The votes keep the class of what the camera saw earlier: the share of all points correctly
  // classed is at least what the camera alone gives.
  EXPECT_GE(e.after_votes.correctShare(), e.per_frame.classifiedShare() * e.per_frame.accuracy());
  EXPECT_GT(e.after_votes.classifiedShare(), e.per_frame.classifiedShare());
  // Unobserved points stay in the map: some segments have a class, most lie outside the picture.
  EXPECT_GT(e.segments_with_class, 0u);
  EXPECT_LT(e.segments_with_class, e.segments / 2);
}

}  // namespace
}  // namespace semsegmap
