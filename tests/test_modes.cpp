// The pipeline's modes end to end on the tiny simulated world: build a target map, save and load
// it, localize another run against it, and close the loop of a drifting run. An oracle describer
// (a descriptor from the ground-truth instance) isolates the wiring from descriptor quality.
// Without the simulator only the real KITTI sample runs, with the eigenvalue descriptor when the
// build has no libtorch.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <random>

#include "build_options.h"
#include "error_text.h"
#include "kitti_raw_sample.h"
#include "oracle_describer.h"
#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/diagnostics.h"
#include "semsegmap/core/frame_subset.h"
#include "semsegmap/datasets/lidar_odometry_source.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/graph/trajectory.h"
#include "semsegmap/outputs/run_output.h"
#include "semsegmap/pipeline/input_modalities.h"
#include "semsegmap/pipeline/map_parameters.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/pipeline/slam.h"
#include "semsegmap/settings/config.h"

namespace semsegmap {
namespace {

PipelineConfig semsegmapConfig() {
  return loadPipelineConfig(std::string(SEMSEGMAP_SOURCE_DIR) + "/config/semsegmap.yaml");
}

// A stop request (Ctrl-C in the CLI) is checked between frames: the frame in hand finishes, no
// further one starts, and the run says it was interrupted with the frames done.
TEST(Modes, AStopRequestEndsTheRunBetweenFrames) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  auto source = openDataset("sim:world=1,run=S2,preset=tiny,frames=6");
  std::atomic<bool> stop{false};
  RunOptions options;
  options.stop = StopToken(stop);
  std::vector<size_t> processed, reported;
  options.progress = [&](size_t done, size_t total) {
    EXPECT_EQ(total, 6u);
    reported.push_back(done);
  };
  // Asked while frame 2 is processed: frame 2 is finished, frame 3 never starts.
  const bool whole = feedFrames(*source, options, [&](const Frame& frame) {
    processed.push_back(frame.index);
    if (frame.index == 2) stop = true;
  });
  EXPECT_FALSE(whole);
  EXPECT_EQ(processed, (std::vector<size_t>{0, 1, 2}));
  EXPECT_EQ(reported, (std::vector<size_t>{1, 2, 3}));

  // A whole mapping run of the frames done, marked interrupted.
  stop = false;
  options.progress = [&](size_t done, size_t) { stop = stop || done == 2; };
  const MappingRun map = runMapping(*source, semsegmapConfig(), PoseSource::kGroundTruth,
                                    std::make_shared<OracleDescriber>(), options);
  EXPECT_TRUE(map.stats.interrupted);
  EXPECT_EQ(map.stats.frames, 2u);
  EXPECT_EQ(map.trajectory.size(), 2u);

  // Asked before the first frame: nothing done, and finishing the empty run is safe.
  stop = true;
  options.progress = nullptr;
  const SlamRun slam =
      runSlam(*source, semsegmapConfig(), std::make_shared<OracleDescriber>(), options);
  EXPECT_TRUE(slam.stats.interrupted);
  EXPECT_EQ(slam.stats.frames, 0u);
  EXPECT_TRUE(slam.trajectory.empty());
  EXPECT_TRUE(nlohmann::json::parse(slamSummaryJson(slam, "tiny"))["interrupted"].get<bool>());

  // Without a request every frame runs and nothing says interrupted.
  stop = false;
  const MappingRun all = runMapping(*source, semsegmapConfig(), PoseSource::kGroundTruth,
                                    std::make_shared<OracleDescriber>(), options);
  EXPECT_FALSE(all.stats.interrupted);
  EXPECT_EQ(all.stats.frames, 6u);
}

TEST(Modes, MapSaveLoadAndLocalizeAnotherRunOfTheSamePlace) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  const PipelineConfig config = semsegmapConfig();
  const auto oracle = std::make_shared<OracleDescriber>();
  auto mapping = openDataset("sim:world=1,run=S2,preset=tiny,frames=60");
  const MappingRun mapped = runMapping(*mapping, config, PoseSource::kGroundTruth, oracle);
  ASSERT_GT(mapped.map.size(), 10u);
  EXPECT_EQ(mapped.map.descriptor, "eigen");
  EXPECT_EQ(mapped.map.fingerprint, "oracle");
  EXPECT_EQ(mapped.stats.frames, 60u);
  EXPECT_EQ(mapped.map.size() + mapped.duplicates_removed, mapped.segments);

  const auto path = std::filesystem::temp_directory_path() / "semsegmap_test_modes.map";
  saveTargetMap(path, mapped.map);
  const auto map = std::make_shared<const TargetMap>(loadTargetMap(path));

  // Another condition and other traffic on the same route; poses from drifting odometry.
  auto query = openDataset("sim:world=1,run=S2,preset=tiny,frames=60,condition=sunrise,traffic=9");
  const LocalizationRun run = runLocalization(*query, config, map, oracle);
  const LocalizationSummary s = summarize(run.localizations);
  EXPECT_GT(s.localizations, 20u);
  EXPECT_EQ(s.with_ground_truth, s.localizations);
  EXPECT_EQ(s.below_1m.value(), s.localizations);  // true matches only: every pose is right
  EXPECT_LT(s.mean_rotation_error_deg.value(), 2.0);
  for (const LocalizationRecord& r : run.localizations) {
    EXPECT_GE(r.inliers, config.localization.localizer.verification.min_inliers);
    ASSERT_EQ(r.matches.size(), static_cast<size_t>(r.inliers));
    // The matched centroids, carried into the map by the estimate, land on their targets.
    for (const auto& [local, target] : r.matches) EXPECT_LT((local - target).norm(), 1.0f);
  }
  EXPECT_EQ(run.stats.frames, 60u);
  EXPECT_GT(run.stats.fps(), 0.0);

  SummaryContext context;
  context.map_segments = map->size();
  const std::string json = localizationSummaryJson(run, context);
  for (const char* key : {"schema", "n_localizations", "n_with_ground_truth", "n_error_below_1m",
                          "n_error_below_5m", "mean_translation_error_m", "mean_rotation_error_deg",
                          "fps", "stage_ms", "map_segments", "map_bytes"})
    EXPECT_NE(json.find(std::string("\"") + key + "\""), std::string::npos) << key;
}

// target_map.earlier_observations_apart_m: the map holds every final observation it holds
// without, and besides them earlier observations of the same segments, each at least that far
// from its segment's final one (the oracle describes an instance the same in every observation).
TEST(Modes, AMapKeepsEarlierObservationsApartFromTheFinalOnes) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  PipelineConfig config = semsegmapConfig();
  config.target_map.duplicate_distance_m = 0;  // every entry stays: compare them one by one
  const auto oracle = std::make_shared<OracleDescriber>();
  auto mapping = openDataset("sim:world=1,run=S2,preset=tiny,frames=60");
  const TargetMap final_only = runMapping(*mapping, config, PoseSource::kGroundTruth, oracle).map;
  config.target_map.earlier_observations_apart_m = 1.0;
  const MappingRun run = runMapping(*mapping, config, PoseSource::kGroundTruth, oracle);
  const TargetMap& with = run.map;
  ASSERT_GT(with.size(), final_only.size());
  auto rowOf = [](const TargetMap& map, size_t i) {
    return Eigen::VectorXf(map.descriptors.row(static_cast<Eigen::Index>(i)).transpose());
  };
  std::vector<bool> final(with.size(), false);
  for (size_t i = 0; i < final_only.size(); ++i) {
    bool found = false;
    for (size_t j = 0; j < with.size() && !found; ++j)
      if ((with.segments[j].centroid - final_only.segments[i].centroid).norm() < 1e-6f &&
          rowOf(with, j) == rowOf(final_only, i))
        found = final[j] = true;
    EXPECT_TRUE(found) << "final observation " << i << " is missing";
  }
  size_t earlier = 0, apart = 0;
  for (size_t j = 0; j < with.size(); ++j) {
    if (final[j]) continue;
    ++earlier;
    // Its instance's final observations (a segment may have merged with another since).
    float nearest = std::numeric_limits<float>::infinity();
    for (size_t i = 0; i < with.size(); ++i)
      if (final[i] && rowOf(with, i) == rowOf(with, j))
        nearest = std::min(nearest, (with.segments[i].centroid - with.segments[j].centroid).norm());
    apart += nearest >= 1.0f;
  }
  EXPECT_EQ(earlier, with.size() - final_only.size());
  EXPECT_EQ(run.earlier_observations, earlier);
  EXPECT_EQ(run.duplicates_removed, 0u);
  EXPECT_GE(apart, earlier * 8 / 10) << "of " << earlier << " earlier observations";
}

// A descriptor of what one observation saw: its point count and extent. A segment seen by more
// scans is described otherwise, so only the same cut of the same scan matches exactly.
class ObservationDescriber : public Describer {
 public:
  DescriptorKind kind() const override { return DescriptorKind::kEigen; }
  int dimension() const override { return 4; }
  std::string fingerprint() const override { return "observation"; }
  Eigen::MatrixXf describe(const std::vector<DescriptorInput>& batch) override {
    Eigen::MatrixXf out(static_cast<Eigen::Index>(batch.size()), 4);
    for (size_t i = 0; i < batch.size(); ++i) {
      Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e9f), hi = -lo;
      for (const EnrichedPoint& p : *batch[i].points) {
        lo = lo.cwiseMin(Eigen::Vector3f(p.x, p.y, p.z));
        hi = hi.cwiseMax(Eigen::Vector3f(p.x, p.y, p.z));
      }
      const auto row = static_cast<Eigen::Index>(i);
      out(row, 0) = static_cast<float>(batch[i].points->size()) / 100.0f;
      out.block<1, 3>(row, 1) = (hi - lo).transpose();
    }
    return out;
  }
};

// localization.latest_scan_fallback_m: scans far apart leave the local map holding the place as
// several scans saw it; the map here holds it as one scan did. Frame 40 after frame 20 (about
// 20 m): the local map's segments are not the map's, the latest scan's own are.
TEST(Modes, ScansFarApartLocalizeFromTheLatestScanWhenTheLocalMapDoesNot) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  PipelineConfig config = semsegmapConfig();
  const auto describer = std::make_shared<ObservationDescriber>();
  auto run = openDataset("sim:world=1,run=S2,preset=tiny,frames=60");
  FrameSubset one_scan(*run, {40});
  const auto map = std::make_shared<const TargetMap>(
      runMapping(one_scan, config, PoseSource::kGroundTruth, describer).map);
  ASSERT_GT(map->size(), 10u);
  FrameSubset query(*run, {20, 40});
  const double moved =
      (query.frame(1).T_odom_base.translation() - query.frame(0).T_odom_base.translation()).norm();
  ASSERT_GT(moved, 10.0);

  const LocalizationRun without = runLocalization(query, config, map, describer);
  for (const LocalizationRecord& r : without.localizations)
    EXPECT_NE(r.frame_index, 1u) << "the local map of both scans localized";
  config.localization.latest_scan_fallback_m = moved + 1.0;  // farther than the scans lie apart
  EXPECT_TRUE(runLocalization(query, config, map, describer).localizations.empty());

  config.localization.latest_scan_fallback_m = 5.0;
  const LocalizationRun with = runLocalization(query, config, map, describer);
  ASSERT_EQ(with.localizations.size(), 1u);
  const LocalizationRecord& r = with.localizations[0];
  EXPECT_EQ(r.frame_index, 1u);
  EXPECT_EQ(r.path, LocalizationPath::kLatestScan);
  EXPECT_LT(r.translation_error_m, 0.05);
  EXPECT_LT(r.rotation_error_deg, 0.25);  // 0.19: the points no camera saw are in its segments
}

// localization.relocalization: a robot wakes up (one scan of S2) in a map of S1. The whole-map
// query is made to ask for more consistent matches than one scan gives, so only the
// relocalization path (places voted for, fewer inliers, the registration check) can localize it;
// a map without segment points still localizes with relocalization off, saying so in one line,
// and a prior elsewhere finds nothing.
TEST(Modes, AWakeUpIsRelocalizedFromOneScanAndThePathIsRecorded) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  PipelineConfig config = semsegmapConfig();
  config.target_map.max_points_per_segment = 512;
  const auto describer = std::make_shared<OracleDescriber>();
  auto mapped = openDataset("sim:world=1,run=S1,preset=tiny,frames=80");
  const auto map = std::make_shared<const TargetMap>(
      runMapping(*mapped, config, PoseSource::kGroundTruth, describer).map);
  auto run = openDataset("sim:world=1,run=S2,preset=tiny,frames=80");
  FrameSubset wake_up(*run, {15});  // on S1's street, S1 drove past 25 frames in
  config.localization.localizer.verification.min_inliers = 1000;
  EXPECT_TRUE(runLocalization(wake_up, config, map, describer).localizations.empty());

  config.localization.relocalization.enabled = true;
  const LocalizationRun with = runLocalization(wake_up, config, map, describer);
  ASSERT_EQ(with.localizations.size(), 1u);
  const LocalizationRecord& r = with.localizations[0];
  EXPECT_EQ(r.path, LocalizationPath::kRelocalization);
  ASSERT_TRUE(r.registration_fitness);
  EXPECT_GE(*r.registration_fitness, config.localization.relocalization.check.min_fitness);
  EXPECT_LT(r.translation_error_m, 0.3);
  EXPECT_LT(r.rotation_error_deg, 1.0);

  // The one-scan call gives the same pose, whatever the config says, and leaves the run alone.
  config.localization.relocalization.enabled = false;
  const LocalizationSession session(config, run->info(), map, describer);
  const std::optional<LocalizationRecord> one = session.relocalize(wake_up.frame(0));
  ASSERT_TRUE(one);
  EXPECT_EQ(one->path, LocalizationPath::kRelocalization);
  EXPECT_TRUE(one->T_map_base.isApprox(r.T_map_base, 1e-9));
  EXPECT_TRUE(session.run().localizations.empty());
  config.localization.relocalization.enabled = true;

  const RelocalizationPrior elsewhere{r.T_map_base.translation() + Eigen::Vector3d(300, 0, 0),
                                      50.0};
  EXPECT_TRUE(
      runLocalization(wake_up, config, map, describer, {}, MapSettingsCheck::kRefuse, elsewhere)
          .localizations.empty());

  // The pose's covariance comes from the registration: finite, no looser than its floors, and
  // the robot's true position within three of its sigmas.
  const Eigen::Matrix<double, 6, 1> sigmas = sigmasOf(r.covariance);
  EXPECT_TRUE(sigmas.allFinite());
  EXPECT_GE(sigmas[0], config.localization.covariance.min_sigma_m);
  EXPECT_LT(sigmas.head<2>().maxCoeff(), 1.0) << sigmas.transpose();
  EXPECT_LE(positionNees(r.covariance, r.T_map_base.translation() - r.T_world_base->translation()),
            9.0);

  for (const size_t points : {size_t{0}, size_t{32}}) {
    TargetMap few = *map;
    for (MapSegment& s : few.segments) s.points = subsamplePoints(s.points, points);
    if (points == 0)
      for (MapSegment& s : few.segments) s.points.clear();
    few.source = "few.map";
    std::vector<std::string> notes;
    setMessageSink([&](const std::string& line) { notes.push_back(line); });
    config.localization.localizer.verification.min_inliers = 6;
    config.localization.refinement.enabled = false;
    std::vector<size_t> frames(20);
    std::iota(frames.begin(), frames.end(), size_t{10});
    FrameSubset drive(*run, frames);
    const LocalizationRun run_few =
        runLocalization(drive, config, std::make_shared<const TargetMap>(few), describer);
    setMessageSink({});
    EXPECT_FALSE(run_few.localizations.empty()) << "it still localizes";
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_MENTIONS(notes[0], "few.map: keeps ");
    EXPECT_MENTIONS(notes[0], "relocalization is off for this run; rebuild the map with");
    config.localization.localizer.verification.min_inliers = 1000;
  }
}

// localization.relocalization.scan_context: a map with segment points and
// target_map.scan_context_apart_m keeps the scan context of a scan every metre (one without
// points keeps none); a wake-up's own scan context proposes its place even
// where no place has the votes to be verified, and the registration check gives the pose.
TEST(Modes, AWakeUpIsRelocalizedFromItsScanContextWhereNoPlaceIsVotedFor) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  PipelineConfig config = semsegmapConfig();
  config.target_map.scan_context_apart_m = 1.0;
  const auto describer = std::make_shared<OracleDescriber>();
  auto mapped = openDataset("sim:world=1,run=S1,preset=tiny,frames=80");
  FrameSubset few(*mapped, {0, 1, 2});
  EXPECT_EQ(runMapping(few, config, PoseSource::kGroundTruth, describer).map.scan_contexts.size(),
            0u);
  config.target_map.max_points_per_segment = 512;
  const auto map = std::make_shared<const TargetMap>(
      runMapping(*mapped, config, PoseSource::kGroundTruth, describer).map);
  const auto& scans = map->scan_contexts.scans();
  ASSERT_GE(scans.size(), 20u);
  for (size_t i = 1; i < scans.size(); ++i)
    EXPECT_GE(
        (scans[i].T_world_scan.translation() - scans[i - 1].T_world_scan.translation()).norm(),
        config.target_map.scan_context_apart_m);

  auto run = openDataset("sim:world=1,run=S2,preset=tiny,frames=80");
  FrameSubset wake_up(*run, {15});
  config.localization.localizer.verification.min_inliers = 1000;
  config.localization.relocalization.enabled = true;
  config.localization.relocalization.min_votes = 100000;  // no place is verified
  const LocalizationRun with = runLocalization(wake_up, config, map, describer);
  ASSERT_EQ(with.localizations.size(), 1u);
  const LocalizationRecord& r = with.localizations[0];
  EXPECT_EQ(r.path, LocalizationPath::kScanContext);
  EXPECT_LT(r.translation_error_m, 0.3);
  EXPECT_LT(r.rotation_error_deg, 1.0);
  config.localization.relocalization.scan_context = false;
  EXPECT_TRUE(runLocalization(wake_up, config, map, describer).localizations.empty());
}

// Segments leave the local map finished (their views go into the map), absorbed (their views go
// to the survivor) or dropped as too large and then gone: the session holds views only of
// segments still in the local map, so a long run's memory stays that of its local map.
TEST(Modes, EarlierObservationsAreHeldOnlyForSegmentsStillInTheLocalMap) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  PipelineConfig config = semsegmapConfig();
  config.target_map.earlier_observations_apart_m = 1.0;
  config.segmentation.max_segment_points = 1500;  // some are dropped as too large, then leave
  auto source = openDataset("sim:world=1,run=S2,preset=tiny,frames=60");
  MappingSession session(config, source->info(), PoseSource::kGroundTruth,
                         std::make_shared<OracleDescriber>());
  size_t held = 0, gone = 0;
  for (size_t i = 0; i < source->size(); ++i) {
    session.process(source->frame(i));
    for (SegmentId id : session.segmentsWithEarlierObservations()) {
      ++held;
      gone += session.pipeline().segmenter().segment(id) == nullptr;
    }
  }
  EXPECT_GT(held, 100u);
  EXPECT_EQ(gone, 0u) << "views held for segments that left the local map";
  EXPECT_GT(session.finish().earlier_observations, 0u);
}

// The local segments a localization queries are exactly the segmenter's reported ones: absorbed,
// finished and dropped segments leave at once. A dropped one left behind stayed in every query
// to the end of the run, and a long run's queries (and their geometric check) grew without bound.
TEST(Modes, LocalSegmentsAreTheSegmentsStillReported) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  PipelineConfig config = semsegmapConfig();
  config.segmentation.max_segment_points = 1500;  // some are dropped as too large
  auto source = openDataset("sim:world=1,run=S2,preset=tiny,frames=120");
  Pipeline pipeline(config, source->info(), PoseSource::kGroundTruth,
                    std::make_shared<OracleDescriber>());
  size_t dropped = 0, stale = 0;
  for (size_t i = 0; i < source->size(); ++i) {
    dropped += pipeline.process(source->frame(i)).segmentation.dropped.size();
    std::vector<SegmentId> reported;
    for (const Segment* s : pipeline.segmenter().activeSegments()) reported.push_back(s->id);
    for (const SegmentId id : pipeline.localSegmentQuery().ids)
      stale += !std::binary_search(reported.begin(), reported.end(), id);
  }
  EXPECT_GT(dropped, 0u) << "the run must drop a described segment for this to test anything";
  EXPECT_EQ(stale, 0u) << "query entries for segments no longer reported";
}

// A run that localized nothing has no mean error: null, never a 0 that reads as perfect.
TEST(Modes, SummaryOfARunWithoutLocalizationsHasNoMeanError) {
  LocalizationRun run;
  run.trajectory_gt.assign(3, Pose::Identity());
  run.stats.frames = 3;
  const std::string json = localizationSummaryJson(run, SummaryContext{});
  EXPECT_NE(json.find("\"mean_translation_error_m\": null"), std::string::npos) << json;
  EXPECT_NE(json.find("\"mean_rotation_error_deg\": null"), std::string::npos) << json;
  // With ground truth, none of no localization is within 1 m: a count, known.
  EXPECT_NE(json.find("\"n_error_below_1m\": 0"), std::string::npos) << json;
}

// Localizations without ground truth: how many were within 1 m is unknown, null like the mean
// errors (a 0 read as "none right"), and the file says its schema.
TEST(Modes, SummaryWithoutGroundTruthHasNullCountsAndErrors) {
  LocalizationRun run;
  run.stats.frames = 2;
  LocalizationRecord r;
  r.inliers = 7;
  run.localizations.assign(2, r);
  const std::string json = localizationSummaryJson(run, SummaryContext{});
  EXPECT_NE(json.find("\"schema\": \"semsegmap.localization/4\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"n_localizations\": 2"), std::string::npos) << json;
  EXPECT_NE(json.find("\"n_with_ground_truth\": 0"), std::string::npos) << json;
  for (const char* key : {"n_error_below_1m", "n_error_below_5m", "mean_translation_error_m",
                          "mean_rotation_error_deg"})
    EXPECT_NE(json.find("\"" + std::string(key) + "\": null"), std::string::npos) << key << json;
  const LocalizationSummary s = summarize(run);
  EXPECT_FALSE(s.below_1m.has_value());
  EXPECT_FALSE(s.mean_translation_error_m.has_value());
}

// Some localizations with ground truth, some without: the means are over those measured, the
// counts unknown (how many of the others were within 1 m is not known).
TEST(Modes, SummaryOfPartlyMeasuredLocalizations) {
  std::vector<LocalizationRecord> records(3);
  records[0].T_world_base = Pose::Identity();
  records[0].translation_error_m = 0.5;
  records[0].rotation_error_deg = 1.0;
  records[1].T_world_base = Pose::Identity();
  records[1].translation_error_m = 3.5;
  records[1].rotation_error_deg = 3.0;
  const LocalizationSummary partly = summarize(records);
  EXPECT_EQ(partly.localizations, 3u);
  EXPECT_EQ(partly.with_ground_truth, 2u);
  EXPECT_FALSE(partly.below_1m.has_value());
  EXPECT_DOUBLE_EQ(partly.mean_translation_error_m.value(), 2.0);
  records.pop_back();
  const LocalizationSummary all = summarize(records);
  EXPECT_EQ(all.below_1m, std::optional<size_t>(1));
  EXPECT_EQ(all.below_5m, std::optional<size_t>(2));
  EXPECT_DOUBLE_EQ(all.mean_rotation_error_deg.value(), 2.0);
}

// The session itself (not only the CLI) compares the map's recorded settings with its own: a
// library user localizing against a map grown with another growing radius is refused, or warned
// of each difference when they allow it.
TEST(Modes, LocalizationRefusesAMapBuiltWithOtherSettingsUnlessAllowed) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  const auto oracle = std::make_shared<OracleDescriber>();
  auto mapping = openDataset("sim:world=1,run=S2,preset=tiny,frames=10");
  auto map = std::make_shared<TargetMap>(
      runMapping(*mapping, semsegmapConfig(), PoseSource::kGroundTruth, oracle).map);
  map->source = "built.map";
  PipelineConfig other = semsegmapConfig();
  other.segmentation.d_segment_m = 0.5;
  auto query = openDataset("sim:world=1,run=S2,preset=tiny,frames=2");
  try {
    runLocalization(*query, other, map, oracle);
    ADD_FAILURE() << "a map built with d_segment_m 0.3 was accepted with 0.5";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              "built.map: segmentation.d_segment_m: the map was built with 0.3, the configuration "
              "has 0.5 (rebuild the map with this configuration)");
  }
  std::vector<std::string> warnings;
  setMessageSink([&](const std::string& line) { warnings.push_back(line); });
  const LocalizationRun run =
      runLocalization(*query, other, map, oracle, {}, MapSettingsCheck::kWarn);
  setMessageSink({});
  EXPECT_EQ(run.stats.frames, 2u);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_EQ(warnings[1],
            "warning:   built.map: segmentation.d_segment_m: the map was built with 0.3, the "
            "configuration has 0.5");
  // A map that records no settings (made by hand) has nothing to compare.
  map->parameters.clear();
  EXPECT_NO_THROW(runLocalization(*query, other, map, oracle));
}

// Before unobserved points were told apart from class unknown, remove_unknown_class dropped both:
// an old map that lacks remove_unobserved is read as built with it equal to remove_unknown_class.
TEST(Modes, AMapOfAnOlderBuildReadsItsUnobservedRuleFromRemoveUnknownClass) {
  PipelineConfig config = semsegmapConfig();
  MapParameters old_map = mapParametersOf(config);
  const auto key = [](const std::string& k) {
    return [k](const std::pair<std::string, std::string>& kv) { return kv.first == k; };
  };
  old_map.erase(std::remove_if(old_map.begin(), old_map.end(), key("local_map.remove_unobserved")),
                old_map.end());
  config.local_map.remove_unobserved = config.local_map.remove_unknown_class;
  EXPECT_EQ(upgradeMapParameters(old_map), mapParametersOf(config));
  TargetMap map;
  map.parameters = old_map;
  EXPECT_NO_THROW(checkMapParameters("old.map", map, config, MapSettingsCheck::kRefuse));
  config.local_map.remove_unobserved = !config.local_map.remove_unknown_class;
  EXPECT_THROW(checkMapParameters("old.map", map, config, MapSettingsCheck::kRefuse),
               std::runtime_error);
  // A map that records the flag keeps what it recorded.
  map.parameters = mapParametersOf(config);
  EXPECT_EQ(upgradeMapParameters(map.parameters), map.parameters);
}

// A session that describes segments refuses to start without a describer, naming itself.
TEST(Modes, SessionsWithoutADescriberAreRefusedAtConstruction) {
  DatasetInfo info;
  info.has_odometry = info.has_ground_truth_poses = true;
  info.classes = ClassTable::Default();
  try {
    MappingSession session(semsegmapConfig(), info, PoseSource::kGroundTruth, nullptr);
    ADD_FAILURE() << "a mapping session without a describer was made";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "MappingSession: no describer given (makeDescriber)");
  }
  EXPECT_THROW(
      LocalizationSession(semsegmapConfig(), info, std::make_shared<const TargetMap>(), nullptr),
      std::invalid_argument);
}

TEST(Modes, LocalizationRefusesAMapOfAnotherModel) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  const auto oracle = std::make_shared<OracleDescriber>();
  auto map = std::make_shared<TargetMap>();
  map->descriptor = "eigen";
  map->fingerprint = "another model";
  map->descriptors.resize(0, 8);
  auto query = openDataset("sim:world=1,run=S2,preset=tiny,frames=2");
  EXPECT_THROW(runLocalization(*query, semsegmapConfig(), map, oracle), std::runtime_error);
}

// Refinement registers the matched segments' points to the map's stored ones. On LiDAR odometry
// the local map keeps the shape of the place, and the poses come much closer to the ground truth
// than the centroids alone put them, every localization kept. (On the simulator's drifting
// odometry the local map itself is bent by the drift, which no rigid registration removes.)
TEST(Modes, PoseRefinementOnLidarOdometryBringsLocalizationsCloserThanCentroidsAlone) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  PipelineConfig config = semsegmapConfig();
  config.target_map.max_points_per_segment = 256;
  const auto oracle = std::make_shared<OracleDescriber>();
  auto mapping = openDataset("sim:world=1,run=S2,preset=tiny,frames=40");
  const auto map = std::make_shared<const TargetMap>(
      runMapping(*mapping, config, PoseSource::kGroundTruth, oracle).map);
  ASSERT_TRUE(hasSegmentPoints(*map));
  const auto localize = [&](const PipelineConfig& c) {
    auto query = withLidarOdometry(
        openDataset("sim:world=1,run=S2,preset=tiny,frames=40,condition=sunrise,traffic=9"),
        OdometryConfig{});
    return runLocalization(*query, c, map, oracle);
  };
  const LocalizationSummary centroids = summarize(localize(config).localizations);
  config.localization.refinement.enabled = true;
  const LocalizationRun refined_run = localize(config);
  const LocalizationSummary refined = summarize(refined_run.localizations);
  ASSERT_GT(centroids.localizations, 20u);
  EXPECT_EQ(refined.localizations, centroids.localizations);
  size_t applied = 0;
  for (const LocalizationRecord& r : refined_run.localizations) applied += r.refined;
  EXPECT_GT(applied, refined.localizations / 2);
  EXPECT_LT(refined.mean_translation_error_m.value(),
            0.5 * centroids.mean_translation_error_m.value());
  EXPECT_LT(refined.mean_translation_error_m.value(), 0.06);
  EXPECT_LT(refined.mean_rotation_error_deg.value(), centroids.mean_rotation_error_deg.value());
}

TEST(Modes, RefinementRefusesAMapWithoutPoints) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  const auto oracle = std::make_shared<OracleDescriber>();
  auto map = std::make_shared<TargetMap>();
  map->descriptor = "eigen";
  map->fingerprint = "oracle";
  map->descriptors.resize(1, 8);
  map->segments.resize(1);
  PipelineConfig config = semsegmapConfig();
  config.localization.refinement.enabled = true;
  auto query = openDataset("sim:world=1,run=S2,preset=tiny,frames=2");
  EXPECT_THROW(runLocalization(*query, config, map, oracle), std::invalid_argument);
}

// The real-data configuration on the ten real KITTI frames (no labels, no poses): the map of the
// drive localizes the same drive again, with the 7 inliers the paper asks for on real data, at
// the identity (odometry is the identity without oxts). The descriptors are the shipped model's,
// trained on simulated data only; in a build without libtorch, the eigenvalue features.
TEST(Modes, RealDataConfigMapsAndLocalizesTheKittiSample) {
  const PipelineConfig config = test_support::realRigConfig();
  EXPECT_EQ(config.localization.localizer.verification.min_inliers, 7);
  SEMSEGMAP_SKIP_WITHOUT_KITTI_RAW_SAMPLE();
  const std::string spec = "kitti-raw:" + test_support::kittiRawSampleRun().string();
  // The shipped model: real data has no instance ids for an oracle.
  const std::shared_ptr<Describer> describer = makeDescriber(config.descriptor, 1);
  // The sample has no oxts: its poses come from LiDAR odometry (identity poses are refused).
  DatasetOptions lidar_odometry;
  lidar_odometry.odometry = "lidar";
  auto mapping = openDataset(spec, lidar_odometry);
  const MappingRun mapped = runMapping(*mapping, config, PoseSource::kOdometry, describer);
  ASSERT_GT(mapped.map.size(), 10u);
  auto query = openDataset(spec, lidar_odometry);
  const LocalizationRun run =
      runLocalization(*query, config, std::make_shared<const TargetMap>(mapped.map), describer);
  EXPECT_TRUE(run.trajectory_gt.empty());
  ASSERT_GE(run.localizations.size(), 3u);
  for (const LocalizationRecord& r : run.localizations) {
    EXPECT_GE(r.inliers, 7);
    // The same drive mapped and localized with the same odometry: the pose in the map is the
    // frame's own odometry pose. Partly seen segments move their centroids, so it is not exact.
    const Pose T_odom_base = query->frame(r.frame_index).T_odom_base;
    EXPECT_LT(translationError(r.T_map_base, T_odom_base), 1.5) << "frame " << r.frame_index;
    EXPECT_LT(rotationErrorDeg(r.T_map_base, T_odom_base), 3.0);
  }
}

TEST(Modes, LoopClosureRemovesOdometryDriftOnALoop) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  PipelineConfig config = semsegmapConfig();
  // The tiny world's block is smaller than the local map: with the default 50 m radius the start
  // of the loop would never leave the local map, so there would be nothing to close.
  config.local_map.radius_m = 30.0;
  config.loop_closure.exclude_recent_m = 40.0;
  // The run ends where it started, so only its last few frames see the start again, and the
  // tiny world has few objects there: 4 true matches are what it offers.
  config.localization.localizer.verification.min_inliers = 4;
  const auto oracle = std::make_shared<OracleDescriber>();
  auto source = openDataset("sim:world=1,run=S2,preset=tiny");
  const SlamRun run = runSlam(*source, config, oracle);
  ASSERT_EQ(run.trajectory.size(), run.trajectory_gt.size());
  EXPECT_GE(run.loops.size(), 1u);
  const std::optional<SlamErrors> errors = slamErrors(run);
  ASSERT_TRUE(errors);
  const double before = errors->odometry.rmse_m, after = errors->slam.rmse_m;
  EXPECT_GT(before, 1.0);  // the run drifts enough for the test to mean something
  EXPECT_LT(after, 0.8 * before) << "before " << before << " after " << after;
  EXPECT_LE(errors->slam_aligned.rmse_m, after + 1e-9);  // alignment only ever helps
  // Loop closures connect the end of the run to its start, not neighbouring frames.
  for (const LoopClosure& l : run.loops) EXPECT_GT(l.node - l.old_node, 40u);

  const nlohmann::json summary = nlohmann::json::parse(slamSummaryJson(run, "tiny S2"));
  EXPECT_EQ(summary["loop_closures"].get<size_t>(), run.loops.size());
  EXPECT_EQ(summary["frames"].get<size_t>(), run.trajectory.size());
  EXPECT_TRUE(summary["has_ground_truth"].get<bool>());
  EXPECT_DOUBLE_EQ(summary["ate_odometry"]["rmse_m"].get<double>(), before);
  EXPECT_DOUBLE_EQ(summary["ate_slam"]["rmse_m"].get<double>(), after);
  EXPECT_DOUBLE_EQ(summary["ate_slam_aligned"]["rmse_m"].get<double>(),
                   errors->slam_aligned.rmse_m);
}

// The summaries escape what they quote: a dataset, map or config name with a quote and a
// backslash reads back as it was. Without ground truth there are no errors to report.
TEST(Modes, SummariesKeepNamesWithQuotesAndBackslashes) {
  const std::string name = "dir/with \"quotes\" and \\ backslash";
  const nlohmann::json slam = nlohmann::json::parse(slamSummaryJson(SlamRun{}, name));
  EXPECT_EQ(slam["dataset"], name);
  EXPECT_FALSE(slam["has_ground_truth"].get<bool>());
  // Without ground truth the errors are unknown: null, as in every summary, not left out.
  ASSERT_TRUE(slam.contains("ate_slam"));
  EXPECT_TRUE(slam["ate_slam"].is_null());
  EXPECT_TRUE(slam["has_frame_times"].get<bool>());
  EXPECT_FALSE(slamErrors(SlamRun{}).has_value());

  SummaryContext context;
  context.dataset = context.map = context.config = name;
  const nlohmann::json loc =
      nlohmann::json::parse(localizationSummaryJson(LocalizationRun{}, context));
  for (const char* key : {"dataset", "map", "config"}) EXPECT_EQ(loc[key], name) << key;
  EXPECT_FALSE(loc["has_ground_truth"].get<bool>());
}

}  // namespace
}  // namespace semsegmap

namespace semsegmap {
namespace {

// What a recording gives decides the descriptor model: a LiDAR without a camera gets the
// configuration's LiDAR-only model, anything with colour or classes the main one.
TEST(Modes, ModelChoiceFollowsTheInputsModalities) {
  DatasetInfo kitti_odometry;  // scans only: no cameras, no point labels
  EXPECT_FALSE(inputModalitiesOf(kitti_odometry).color);
  EXPECT_FALSE(inputModalitiesOf(kitti_odometry).classes);
  EXPECT_EQ(modalitiesText(inputModalitiesOf(kitti_odometry)), "geometry only");
  DatasetInfo labelled = kitti_odometry;  // SemanticKITTI: point classes, no camera
  labelled.has_point_labels = true;
  EXPECT_TRUE(inputModalitiesOf(labelled).classes);
  DatasetInfo instances_only = labelled;
  instances_only.point_labels_have_classes = false;
  EXPECT_FALSE(inputModalitiesOf(instances_only).classes);
  DatasetInfo camera = kitti_odometry;
  camera.rig.cameras.emplace_back();
  EXPECT_EQ(modalitiesText(inputModalitiesOf(camera)), "colour and classes");

  DescriptorConfig d{"semsegmap-net", "main.model", 64, "lidar.model"};
  DescriptorChoice c = chooseDescriptor(d, inputModalitiesOf(kitti_odometry));
  EXPECT_EQ(c.descriptor.model, "lidar.model");
  EXPECT_NE(c.note.find("model_lidar_only"), std::string::npos) << c.note;
  for (const DatasetInfo* info : {&labelled, &camera}) {
    c = chooseDescriptor(d, inputModalitiesOf(*info));
    EXPECT_EQ(c.descriptor.model, "main.model");
    EXPECT_TRUE(c.note.empty()) << c.note;
  }
  // No LiDAR-only model configured: the main one, said loudly.
  d.model_lidar_only.clear();
  c = chooseDescriptor(d, inputModalitiesOf(kitti_odometry));
  EXPECT_EQ(c.descriptor.model, "main.model");
  EXPECT_NE(c.note.find("no colour and no classes"), std::string::npos) << c.note;
  // Descriptors that see geometry only have nothing to choose.
  c = chooseDescriptor(DescriptorConfig{"eigen", "", 64, ""}, inputModalitiesOf(kitti_odometry));
  EXPECT_TRUE(c.note.empty());
  c = chooseDescriptor(DescriptorConfig{"segmap-cnn", "cnn.model", 64, ""},
                       inputModalitiesOf(kitti_odometry));
  EXPECT_EQ(c.descriptor.model, "cnn.model");
  EXPECT_TRUE(c.note.empty()) << c.note;
}

TEST(Modes, SimulatedLidarWithoutCameraIsGeometryOnly) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  auto source = openDataset("sim:world=1,run=S2,preset=tiny,lidar=vlp32,cameras=0,classes=0");
  EXPECT_EQ(modalitiesText(inputModalitiesOf(source->info())), "geometry only");
  EXPECT_EQ(source->info().rig.lidar.rows, 32);
  EXPECT_THROW(openDataset("sim:world=1,preset=tiny,lidar=hdl65"), std::invalid_argument);
}

}  // namespace
}  // namespace semsegmap
