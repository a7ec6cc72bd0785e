#include <gtest/gtest.h>

#include <algorithm>

#include "semsegmap/core/diagnostics.h"
#include "semsegmap/pipeline/pipeline.h"
#include "semsegmap/settings/config.h"
#include "semsegmap/sim/simulator.h"

using namespace semsegmap;

namespace {

std::vector<Segment> runPipeline(const std::string& config_name, bool strip_semantics,
                                 size_t frames) {
  sim::SimConfig c;
  c.world = sim::worldPreset("tiny", 1);
  c.run = sim::Run::S2;
  c.max_frames = frames;
  sim::Simulator simulator(c);
  const PipelineConfig config =
      loadPipelineConfig(std::string(SEMSEGMAP_SOURCE_DIR) + "/config/" + config_name + ".yaml");
  Pipeline pipeline(config, simulator.info(), PoseSource::kGroundTruth);
  std::vector<Segment> segments;
  for (size_t i = 0; i < simulator.size(); ++i) {
    Frame f = simulator.frame(i);
    if (strip_semantics) {
      // Data with no classes at all (like KITTI raw): the pipeline must fall back to geometry.
      // Instances stay, only to measure purity.
      for (auto& cam : f.cameras) cam.label = Image();
      for (auto& l : f.point_labels) l.class_id = cls::kUnknown;
    }
    FrameResult r = pipeline.process(f);
    EXPECT_EQ(r.points, f.points.size());
    for (auto& s : r.segmentation.finished) segments.push_back(std::move(s));
  }
  for (auto& s : pipeline.finish()) segments.push_back(std::move(s));
  return segments;
}

}  // namespace

TEST(Pipeline, SimulatedRunGivesPureSegments) {
  for (const char* config : {"semsegmap", "segmap"}) {
    const std::vector<Segment> segments = runPipeline(config, false, 40);
    ASSERT_GT(segments.size(), 20u) << config;
    double purity = 0.0;
    for (const auto& s : segments) {
      purity += s.last().gt_purity;
      EXPECT_GE(s.last().n_points, 100u);
      EXPECT_LE(s.last().n_points, 15000u);
      EXPECT_NE(s.last().gt_instance, 0) << "simulated points carry their instance";
      // Observations only ever grow by at least 10 % (merges aside, they never shrink).
      for (size_t k = 1; k < s.observations.size(); ++k)
        EXPECT_GE(s.observations[k].n_points * 10, s.observations[k - 1].n_points * 11 - 10);
      EXPECT_EQ(s.completeness(s.observations.size() - 1), 1.0);
    }
    EXPECT_GT(purity / segments.size(), 0.85) << config;
    // Ground and cars are filtered: no segment is mostly road or car.
    for (const auto& s : segments) {
      EXPECT_NE(s.last().majority_class, cls::kRoad);
      EXPECT_NE(s.last().majority_class, cls::kCar);
    }
  }
}

TEST(Pipeline, DataWithoutLabelsFallsBackToGeometricGroundRemoval) {
  const std::vector<Segment> segments = runPipeline("segmap", true, 30);
  ASSERT_GT(segments.size(), 10u);
  // Without removing the ground, one segment would swallow the street; with it, segments stay
  // object-sized and mostly belong to one object.
  double purity = 0.0;
  for (const auto& s : segments) purity += s.last().gt_purity;
  EXPECT_GT(purity / segments.size(), 0.7);
}

// One front camera on a 360-degree LiDAR: unobserved points are kept with their geometry (the
// segments grow around the whole robot, pure, without road), or, with the paper's
// remove_unobserved, dropped with a one-line warning that says what to change.
TEST(Pipeline, AFrontCameraRigKeepsUnobservedPointsAsGeometry) {
  sim::SimConfig c;
  c.world = sim::worldPreset("tiny", 1);
  c.run = sim::Run::S2;
  c.max_frames = 12;
  c.rig.lidar = lidarPreset("hdl64");
  c.camera_names = {"front"};
  sim::Simulator simulator(c);
  PipelineConfig keep =
      loadPipelineConfig(std::string(SEMSEGMAP_SOURCE_DIR) + "/config/semsegmap.yaml");
  keep.local_map.remove_unobserved = false;
  PipelineConfig drop = keep;
  drop.local_map.remove_unobserved = true;
  std::vector<std::string> messages;
  setMessageSink([&](const std::string& line) { messages.push_back(line); });
  Pipeline kept(keep, simulator.info(), PoseSource::kGroundTruth);
  Pipeline dropped(drop, simulator.info(), PoseSource::kGroundTruth);
  size_t inserted_kept = 0, inserted_dropped = 0, unobserved = 0, points = 0;
  for (size_t i = 0; i < simulator.size(); ++i) {
    const Frame f = simulator.frame(i);
    const FrameResult a = kept.process(f), b = dropped.process(f);
    inserted_kept += a.map_update.points_inserted;
    inserted_dropped += b.map_update.points_inserted;
    unobserved += a.map_update.points_unobserved;
    points += a.points;
  }
  std::vector<Segment> segments = kept.finish();
  dropped.finish();
  setMessageSink({});
  EXPECT_GT(unobserved, points / 2);
  EXPECT_GT(inserted_kept, 2 * inserted_dropped);
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_NE(messages[0].find("local_map.remove_unobserved drops the rest"), std::string::npos)
      << messages[0];
  ASSERT_GT(segments.size(), 5u);
  double purity = 0.0;
  for (const auto& s : segments) {
    purity += s.last().gt_purity;
    EXPECT_NE(s.last().majority_class, cls::kRoad);
  }
  EXPECT_GT(purity / segments.size(), 0.8);
}
