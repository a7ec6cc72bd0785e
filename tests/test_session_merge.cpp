// Sessions joining a map ([fleet], pipeline/session_merge.h) on the tiny simulated world, with
// the oracle describer so that the merge is tested rather than descriptor quality: a drive on
// drifting odometry, in a frame far from the map's, joins the map at its true place; what both
// sessions saw becomes one segment with two observations; a drive elsewhere stays separate.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <set>

#include "build_options.h"
#include "kitti_raw_sample.h"
#include "oracle_describer.h"
#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/pipeline/map_tiles.h"
#include "semsegmap/pipeline/session_merge.h"
#include "semsegmap/settings/config.h"

namespace semsegmap {
namespace {

// A drive whose odometry starts in a frame of its own: `offset` away from the world's.
class OffsetOdometry : public FrameSource {
 public:
  OffsetOdometry(std::unique_ptr<FrameSource> source, const Pose& offset)
      : source_(std::move(source)), offset_(offset) {}
  const DatasetInfo& info() const override { return source_->info(); }
  size_t size() const override { return source_->size(); }
  Frame frame(size_t i) override {
    Frame f = source_->frame(i);
    f.T_odom_base = offset_ * f.T_odom_base;
    return f;
  }

 private:
  std::unique_ptr<FrameSource> source_;
  Pose offset_;
};

PipelineConfig config() {
  return loadPipelineConfig(std::string(SEMSEGMAP_SOURCE_DIR) + "/config/semsegmap.yaml");
}

std::shared_ptr<const TargetMap> mapOf(const std::string& spec) {
  auto source = openDataset(spec);
  MappingRun run =
      runMapping(*source, config(), PoseSource::kGroundTruth, std::make_shared<OracleDescriber>());
  run.map.source = spec;
  return std::make_shared<const TargetMap>(std::move(run.map));
}

const Pose kOffset =
    Eigen::Translation3d(300.0, -120.0, 4.0) * Eigen::AngleAxisd(2.0, Eigen::Vector3d::UnitZ());

TEST(SessionMerge, ADriftingSessionJoinsTheMapAtItsTruePlace) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  const auto map = mapOf("sim:world=1,run=S0,preset=tiny,frames=130");
  const std::string spec = "sim:world=1,run=S0,preset=tiny,frames=130,traffic=7";
  OffsetOdometry source(openDataset(spec), kOffset);
  const MergedSession m =
      runSessionMerge(source, config(), map, std::make_shared<OracleDescriber>(), spec, 1796000000);
  ASSERT_TRUE(m.aligned) << m.ties.size() << " localizations";
  EXPECT_GE(m.ties.size(), 10u);

  // Its frames' poses in the map (the world's frame) against the truth: within decimetres,
  // where its odometry was hundreds of metres off.
  ASSERT_EQ(m.map.sessions.size(), 2u);
  const MapSession& s = m.map.sessions[1];
  EXPECT_EQ(s.name, spec);
  EXPECT_EQ(s.merged_unix_s, 1796000000);
  ASSERT_EQ(s.trajectory.size(), 130u);
  auto truth = openDataset(spec);
  double error = 0.0, odometry_error = 0.0;
  for (size_t k = 0; k < s.trajectory.size(); ++k) {
    const Frame f = truth->frame(k);
    error += translationError(s.trajectory[k], *f.T_world_base) / s.trajectory.size();
    odometry_error +=
        translationError(kOffset * f.T_odom_base, *f.T_world_base) / s.trajectory.size();
  }
  EXPECT_GT(odometry_error, 100.0);
  // The ties are as good as localization is (about 0.3 m on this world: a local segment's
  // centroid is that of a partial view, the map's of the whole).
  EXPECT_LT(error, 0.5) << "odometry was " << odometry_error << " m off";
  EXPECT_LT(m.mean_tie_residual_m, 0.5);

  // The older session's entries are unchanged, first; the new ones follow as session 1.
  ASSERT_EQ(m.map.size(), map->size() + m.entries);
  for (size_t i = 0; i < map->size(); ++i) {
    EXPECT_EQ(m.map.segments[i].centroid, map->segments[i].centroid);
    EXPECT_EQ(m.map.segments[i].session, 0u);
  }
  // Both sessions drove the same streets: most new entries observe a segment of the map, each
  // within same_segment_m of an older observation of its class, and of the same object (the
  // oracle's descriptors are equal).
  EXPECT_GT(m.same_segments, m.entries / 2) << m.same_segments << " of " << m.entries;
  const double same_m = config().session_merge.same_segment_m;
  std::map<uint32_t, std::vector<size_t>> by_segment;
  for (size_t i = 0; i < m.map.size(); ++i) by_segment[m.map.segments[i].segment].push_back(i);
  size_t shared = 0, same_object = 0;
  for (const auto& [id, entries] : by_segment) {
    std::set<uint16_t> sessions;
    for (size_t i : entries) sessions.insert(m.map.segments[i].session);
    if (sessions.size() < 2) continue;
    const size_t first = entries.front();
    EXPECT_EQ(m.map.segments[first].session, 0u);
    for (size_t i : entries) {
      if (i == first) continue;
      ++shared;
      EXPECT_LT((m.map.segments[i].centroid - m.map.segments[first].centroid).norm(), same_m);
      EXPECT_EQ(m.map.segments[i].majority_class, m.map.segments[first].majority_class);
      same_object += m.map.descriptors.row(static_cast<Eigen::Index>(i)) ==
                     m.map.descriptors.row(static_cast<Eigen::Index>(first));
    }
  }
  EXPECT_EQ(shared, m.same_segments);
  EXPECT_GE(same_object, shared * 9 / 10) << same_object << " of " << shared;
  EXPECT_LT(by_segment.size(), m.map.size());

  // The merged map saves and loads with its sessions, and a third drive joins it.
  const auto path = std::filesystem::temp_directory_path() / "semsegmap_test_session_merge.map";
  saveTargetMap(path, m.map);
  const auto back = std::make_shared<const TargetMap>(loadTargetMap(path));
  ASSERT_EQ(back->sessions.size(), 2u);
  EXPECT_EQ(back->sessions[1].trajectory.size(), 130u);
  const std::string third = "sim:world=1,run=S3,preset=tiny,frames=60";
  auto source3 = openDataset(third);
  const MergedSession m3 = runSessionMerge(*source3, config(), back,
                                           std::make_shared<OracleDescriber>(), third, 1796000001);
  ASSERT_TRUE(m3.aligned);
  EXPECT_EQ(m3.map.sessions.size(), 3u);
  EXPECT_EQ(m3.map.segments.back().session, 2u);
}

TEST(SessionMerge, ASessionThatNeverLocalizesStaysSeparateInItsOwnFrame) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  const auto map = mapOf("sim:world=1,run=S0,preset=tiny,frames=80");
  const std::string elsewhere = "sim:world=2,run=S0,preset=tiny,frames=80";
  OffsetOdometry source(openDataset(elsewhere), kOffset);
  const MergedSession m =
      runSessionMerge(source, config(), map, std::make_shared<OracleDescriber>(), elsewhere, 0);
  EXPECT_FALSE(m.aligned);
  EXPECT_LT(m.ties.size(), config().session_merge.min_localizations);
  // Its own map: one session, its entries where its odometry put them, not at the map's origin.
  ASSERT_EQ(m.map.sessions.size(), 1u);
  EXPECT_EQ(m.map.sessions[0].name, elsewhere);
  ASSERT_EQ(m.map.size(), m.entries);
  ASSERT_EQ(m.map.size(), m.mapping.map.size());
  for (size_t i = 0; i < m.map.size(); ++i)
    EXPECT_EQ(m.map.segments[i].centroid, m.mapping.map.segments[i].centroid);
  EXPECT_EQ(m.map.sessions[0].trajectory.size(), 80u);
  EXPECT_LT(translationError(m.map.sessions[0].trajectory[0], kOffset * Pose::Identity()),
            translationError(m.map.sessions[0].trajectory[0], Pose::Identity()));
}

// Real data: the KITTI raw sample (one front camera on an HDL-64E, LiDAR odometry, the real-data
// configuration and its shipped model) mapped, then driven again in a frame 300 m away: it
// joins where the first drive was, and sees the same segments.
TEST(SessionMerge, TheRealKittiSampleJoinsItsOwnMapFromAnotherFrame) {
  SEMSEGMAP_SKIP_WITHOUT_KITTI_RAW_SAMPLE();
  const PipelineConfig real = test_support::realRigConfig();
  const std::string spec = "kitti-raw:" + test_support::kittiRawSampleRun().string();
  const std::shared_ptr<Describer> describer = makeDescriber(real.descriptor, 1);
  DatasetOptions lidar_odometry;
  lidar_odometry.odometry = "lidar";
  auto first = openDataset(spec, lidar_odometry);
  const MappingRun mapped = runMapping(*first, real, PoseSource::kOdometry, describer);
  const auto map = std::make_shared<const TargetMap>(mapped.map);
  OffsetOdometry again(openDataset(spec, lidar_odometry), kOffset);
  const MergedSession m = runSessionMerge(again, real, map, describer, "again", 0);
  ASSERT_TRUE(m.aligned) << m.ties.size() << " localizations";
  ASSERT_EQ(m.map.sessions.size(), 2u);
  const std::vector<Pose>& joined = m.map.sessions[1].trajectory;
  ASSERT_EQ(joined.size(), mapped.trajectory.size());
  for (size_t k = 0; k < joined.size(); ++k)  // partial views move centroids: not exact
    EXPECT_LT(translationError(joined[k], mapped.trajectory[k]), 1.0) << "frame " << k;
  EXPECT_GT(m.same_segments, m.entries / 2) << m.same_segments << " of " << m.entries;
}

// A map of other settings or another describer is refused before any frame, naming the map.
TEST(SessionMerge, AMapOfOtherSettingsIsRefusedNamingIt) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  auto map = std::make_shared<TargetMap>(*mapOf("sim:world=1,run=S0,preset=tiny,frames=5"));
  map->source = "A.map";
  auto source = openDataset("sim:world=1,run=S2,preset=tiny,frames=5");
  PipelineConfig other = config();
  other.segmentation.d_segment_m = 0.5;
  try {
    SessionMerge merge(other, source->info(), map, std::make_shared<OracleDescriber>());
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("A.map: segmentation.d_segment_m"), std::string::npos)
        << e.what();
  }
}

// A map served in tiles from memory, as a store serves it (store/store_tiles.h): the entries of
// the square tiles that touch the disc around the robot, each tile once.
class MemoryTiles : public MapTileSource {
 public:
  MemoryTiles(std::shared_ptr<const TargetMap> map, Eigen::Vector2d centre, double radius_m)
      : map_(std::move(map)), centre_(centre), radius_m_(radius_m) {}
  TargetMap around(double x, double y) override {
    centre_ = {x, y};
    ++calls_;
    TargetMap out = *map_;
    out.segments.clear();
    std::vector<Eigen::Index> rows;
    for (size_t i = 0; i < map_->size(); ++i) {
      const Eigen::Vector3f& c = map_->segments[i].centroid;
      const std::pair<long, long> tile{std::lround(std::floor(c.x() / kTile)),
                                       std::lround(std::floor(c.y() / kTile))};
      const double dx = std::max({tile.first * kTile - x, 0.0, x - (tile.first + 1) * kTile});
      const double dy = std::max({tile.second * kTile - y, 0.0, y - (tile.second + 1) * kTile});
      if (dx * dx + dy * dy > radius_m_ * radius_m_ || given_.count(i)) continue;
      given_.insert(i);
      out.segments.push_back(map_->segments[i]);
      rows.push_back(static_cast<Eigen::Index>(i));
    }
    out.descriptors.resize(static_cast<Eigen::Index>(rows.size()), map_->dimension());
    for (size_t k = 0; k < rows.size(); ++k)
      out.descriptors.row(static_cast<Eigen::Index>(k)) = map_->descriptors.row(rows[k]);
    return out;
  }
  Eigen::Vector2d centre() const override { return centre_; }
  double reloadAfterM() const override { return kTile / 2; }
  size_t calls() const { return calls_; }
  size_t given() const { return given_.size(); }

 private:
  static constexpr double kTile = 40.0;
  std::shared_ptr<const TargetMap> map_;
  Eigen::Vector2d centre_;
  double radius_m_;
  size_t calls_ = 0;
  std::set<size_t> given_;
};

// A robot that starts with the tiles around its start alone finds itself further on, in tiles
// asked for as it moves, as often as with the whole map.
TEST(MapTiles, ALocalizationFollowsTheTilesAheadAsTheRobotMoves) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  const auto map = mapOf("sim:world=1,run=S0,preset=tiny,frames=110");
  const std::string spec = "sim:world=1,run=S0,preset=tiny,frames=110,traffic=7";
  auto describer = std::make_shared<OracleDescriber>();
  auto whole_source = openDataset(spec);
  const LocalizationRun whole = runLocalization(*whole_source, config(), map, describer);
  const Eigen::Vector2d start = whole.trajectory_gt.front().translation().head<2>();
  auto tiles = std::make_shared<MemoryTiles>(map, start, 25.0);
  const auto first = std::make_shared<const TargetMap>(tiles->around(start.x(), start.y()));
  ASSERT_LT(first->size(), map->size() * 2 / 3) << "the first tiles must not hold the map";
  auto source = openDataset(spec);
  const LocalizationRun tiled = runLocalization(*source, config(), first, describer, {},
                                                MapSettingsCheck::kRefuse, std::nullopt, tiles);
  EXPECT_GT(tiles->calls(), 2u);
  EXPECT_GT(tiles->given(), first->size());
  size_t within = 0, far_within = 0, whole_within = 0;
  for (const LocalizationRecord& r : tiled.localizations) {
    within += r.translation_error_m < 1.0;
    far_within += r.translation_error_m < 1.0 &&
                  (r.T_world_base->translation().head<2>() - start).norm() > 60.0;
  }
  for (const LocalizationRecord& r : whole.localizations)
    whole_within += r.translation_error_m < 1.0;
  EXPECT_GT(far_within, 0u) << "no localization beyond the first tiles";
  EXPECT_GE(within * 10, whole_within * 9) << within << " against " << whole_within;
}

}  // namespace
}  // namespace semsegmap
