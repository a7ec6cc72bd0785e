#include <gtest/gtest.h>

#include <cmath>

#include "semsegmap/local_map/ground_removal.h"
#include "semsegmap/local_map/local_map.h"

using namespace semsegmap;

namespace {

EnrichedPoint point(float x, float y, float z, ClassId c = cls::kBuilding, float hue = 0.5f,
                    bool colored = true) {
  EnrichedPoint p;
  p.x = x;
  p.y = y;
  p.z = z;
  p.h = hue;
  p.s = 0.5f;
  p.v = 0.5f;
  p.class_id = c;
  p.has_class = true;
  p.has_color = colored;
  return p;
}

// A point no camera saw: geometry alone.
EnrichedPoint unobserved(float x, float y, float z) {
  EnrichedPoint p;
  p.x = x;
  p.y = y;
  p.z = z;
  return p;
}

// Road under x (its class removes it): unobserved points above it are not its ground.
EnrichedPoint road(float x) {
  return point(x, 0.05f, 0.0f, cls::kRoad);
}

// A 6 x 6 m patch of ground at z = 0 (10 cm apart) and a 2 m high wall standing on it at x = 2.
EnrichedCloud groundAndWall(bool observed) {
  EnrichedCloud scan;
  for (int i = 0; i < 60; ++i)
    for (int j = 0; j < 60; ++j) {
      const float x = -3.0f + 0.1f * i + 0.05f, y = -3.0f + 0.1f * j + 0.05f;
      scan.push_back(observed ? point(x, y, 0.0f, cls::kRoad) : unobserved(x, y, 0.0f));
    }
  for (int j = 0; j < 20; ++j)
    for (int k = 1; k <= 20; ++k) {
      const float y = -1.0f + 0.1f * j + 0.05f, z = 0.1f * k;
      scan.push_back(observed ? point(2.05f, y, z, cls::kBuilding) : unobserved(2.05f, y, z));
    }
  return scan;
}

LocalMap makeMap(LocalMapConfig c = {}) {
  return LocalMap(c, ClassTable::Default());
}

}  // namespace

TEST(VoxelKey, PackUnpackRoundTrip) {
  for (const Eigen::Vector3i& i : {Eigen::Vector3i(0, 0, 0), Eigen::Vector3i(-1, 2, -3),
                                   Eigen::Vector3i(1000000, -1000000, 5)})
    EXPECT_EQ(unpackVoxelKey(packVoxelKey(i)), i);
  EXPECT_NE(packVoxelKey({1, 0, 0}), packVoxelKey({0, 1, 0}));
}

TEST(LocalMap, HueIsAveragedAsAnAngleAcrossTheWrap) {
  LocalMap map = makeMap();
  map.update({point(0.05f, 0.05f, 1.05f, cls::kBuilding, 0.95f),
              point(0.05f, 0.05f, 1.05f, cls::kBuilding, 0.05f)},
             Pose::Identity(), {0, 0});
  ASSERT_EQ(map.size(), 1u);
  const Voxel& v = map.voxels().begin()->second;
  const float h = v.hue();
  EXPECT_LT(std::min(h, 1.0f - h), 1e-4f) << h;  // 0.0, not the naive 0.5
  EXPECT_EQ(v.n_points, 2u);
  EXPECT_EQ(v.n_colored, 2u);
  // Uncoloured points count for geometry, not for colour.
  map.update({point(0.05f, 0.05f, 1.05f, cls::kBuilding, 0.5f, false)}, Pose::Identity(), {0, 0});
  EXPECT_EQ(map.voxels().begin()->second.n_colored, 2u);
  EXPECT_NEAR(map.voxels().begin()->second.centroid.x(), 0.05f, 1e-6f);
}

TEST(LocalMap, ClassVotesTakeTheMajorityWithoutOverflow) {
  LocalMap map = makeMap();
  EnrichedCloud scan;
  for (int k = 0; k < 600; ++k) scan.push_back(point(0.01f, 0.01f, 1.01f, cls::kVegetation));
  for (int k = 0; k < 300; ++k) scan.push_back(point(0.01f, 0.01f, 1.01f, cls::kFence));
  map.update(scan, Pose::Identity(), {0, 0});
  const Voxel& v = map.voxels().begin()->second;
  EXPECT_EQ(v.semanticClass(), cls::kVegetation);
  EXPECT_EQ(v.classes.countOf(cls::kVegetation), 600u);  // past 255: no 8-bit counters
  EXPECT_EQ(v.classes.countOf(cls::kFence), 300u);
}

TEST(Votes, MajorityKeptWhenLabelsOutnumberSlots) {
  Votes<ClassId, 4> votes;
  for (int round = 0; round < 50; ++round) {
    votes.add(7);
    votes.add(7);
    for (ClassId c = 20; c < 26; ++c)
      if (round % 6 == c - 20) votes.add(c);
  }
  EXPECT_EQ(votes.majority().first, 7);
}

TEST(LocalMap, DynamicAndGroundClassesAreRemovedByConfiguration) {
  LocalMapConfig by_point;
  by_point.dynamic_removal = DynamicRemoval::kPoint;
  LocalMap map = makeMap(by_point);
  const LocalMapUpdate u = map.update(
      {point(1, 0, 1, cls::kCar), point(2, 0, 0, cls::kRoad), point(3, 0, 0, cls::kTerrain),
       point(4, 0, 1, cls::kPerson), point(5, 0, 1, cls::kBuilding)},
      Pose::Identity(), {0, 0});
  EXPECT_EQ(u.points_inserted, 1u);
  EXPECT_EQ(u.points_filtered, 4u);
  LocalMapConfig keep;
  keep.remove_dynamic_classes = false;
  keep.remove_ground_classes = false;
  LocalMap all = makeMap(keep);
  EXPECT_EQ(
      all.update({point(1, 0, 1, cls::kCar), point(2, 0, 0, cls::kRoad)}, Pose::Identity(), {0, 0})
          .points_inserted,
      2u);
}

// A real network labels the edge of a moving truck as the building behind it and some building
// pixels as truck. By point, the truck's mislabelled edge survives as a static voxel; by voxel,
// the truck's voxel is dropped whole and the building's mislabelled points stay in its geometry.
TEST(LocalMap, DynamicVoxelsAreDroppedByMajorityVote) {
  EnrichedCloud scan;
  for (int k = 0; k < 4; ++k) scan.push_back(point(5.05f, 0.05f, 1.05f, cls::kCar));  // truck
  scan.push_back(point(5.05f, 0.05f, 1.05f, cls::kBuilding));  // its edge, mislabelled
  for (int k = 0; k < 3; ++k) scan.push_back(point(8.05f, 0.05f, 1.05f, cls::kBuilding));
  scan.push_back(point(8.05f, 0.05f, 1.05f, cls::kCar));  // a building pixel called truck
  const VoxelKey truck = packVoxelKey({50, 0, 10}), wall = packVoxelKey({80, 0, 10});

  LocalMapConfig by_point;
  by_point.dynamic_removal = DynamicRemoval::kPoint;
  LocalMap old_way = makeMap(by_point);
  old_way.update(scan, Pose::Identity(), {0, 0});
  ASSERT_NE(old_way.find(truck), nullptr);
  EXPECT_TRUE(old_way.find(truck)->active);  // the edge survives as a static "building" voxel
  EXPECT_EQ(old_way.find(wall)->n_points, 3u);

  LocalMap map = makeMap();  // by voxel, the default
  const LocalMapUpdate u = map.update(scan, Pose::Identity(), {0, 0});
  EXPECT_EQ(u.newly_active, std::vector<VoxelKey>{wall});
  EXPECT_FALSE(map.find(truck)->active);
  const Voxel& w = *map.find(wall);
  EXPECT_EQ(w.n_points, 4u);  // the mislabelled point is still the wall's geometry
  EXPECT_EQ(w.n_dynamic, 1u);
  EXPECT_EQ(w.semanticClass(), cls::kBuilding);  // but never its class
  // Votes carry over scans: static points arriving later turn the truck voxel static.
  EnrichedCloud later;
  for (int k = 0; k < 4; ++k) later.push_back(point(5.05f, 0.05f, 1.05f, cls::kBuilding));
  EXPECT_EQ(map.update(later, Pose::Identity(), {0, 0}).newly_active, std::vector<VoxelKey>{truck});
  // The share is configurable: with 0.8, 4 of 5 dynamic votes are not enough to drop it.
  LocalMapConfig lenient;
  lenient.dynamic_vote_share = 0.8;
  LocalMap tolerant = makeMap(lenient);
  EXPECT_EQ(tolerant.update(scan, Pose::Identity(), {0, 0}).newly_active.size(), 2u);
  lenient.dynamic_vote_share = 1.0;
  EXPECT_THROW(makeMap(lenient), std::invalid_argument);
}

TEST(LocalMap, VoxelsActivateAtTheMinimumCountAndLeaveTheCylinder) {
  LocalMapConfig c;
  c.min_points_per_voxel = 3;
  c.radius_m = 50.0;
  LocalMap map = makeMap(c);
  EXPECT_TRUE(
      map.update({point(10.05f, 0.05f, 1.05f)}, Pose::Identity(), {0, 0}).newly_active.empty());
  EXPECT_TRUE(
      map.update({point(10.05f, 0.05f, 1.05f)}, Pose::Identity(), {0, 0}).newly_active.empty());
  EXPECT_EQ(map.update({point(10.05f, 0.05f, 1.05f)}, Pose::Identity(), {0, 0}).newly_active.size(),
            1u);
  EXPECT_TRUE(
      map.update({point(10.05f, 0.05f, 1.05f)}, Pose::Identity(), {0, 0}).newly_active.empty());
  EXPECT_EQ(map.activeCount(), 1u);
  // The robot drives 45 m away: still inside the 50 m cylinder.
  EXPECT_TRUE(map.update({}, Pose::Identity(), {55, 0}).removed.empty());
  // 65 m away: the voxel is dropped and reported.
  const LocalMapUpdate u = map.update({}, Pose::Identity(), {75, 0});
  ASSERT_EQ(u.removed.size(), 1u);
  EXPECT_EQ(map.size(), 0u);
  EXPECT_EQ(map.activeCount(), 0u);
}

TEST(LocalMap, PointsAreFusedInTheMapFrame) {
  LocalMap map = makeMap();
  const Pose T = planarPose(100.0, 50.0, 2.0, M_PI / 2);
  map.update({point(1.0f, 0.0f, 0.0f)}, T, {100, 50});
  ASSERT_EQ(map.size(), 1u);
  const Eigen::Vector3f c = map.voxels().begin()->second.centroid;
  EXPECT_NEAR(c.x(), 100.0f, 1e-4f);
  EXPECT_NEAR(c.y(), 51.0f, 1e-4f);
  EXPECT_NEAR(c.z(), 2.0f, 1e-4f);
}

TEST(GroundRemoval, FollowsATiltedGroundWithoutAFixedHeight) {
  // A ground plane pitched by 8 degrees (a Segway leaning forward) and a 1 m box standing on it.
  EnrichedCloud scan;
  const double slope = std::tan(8.0 * M_PI / 180.0);
  for (float x = -20; x <= 20; x += 0.25f)
    for (float y = -10; y <= 10; y += 0.25f)
      scan.push_back(point(x, y, static_cast<float>(slope * x), cls::kUnknown));
  const size_t ground_points = scan.size();
  for (float z = 0.3f; z <= 1.0f; z += 0.1f)
    for (float y = -0.5f; y <= 0.5f; y += 0.1f)
      scan.push_back(point(15.0f, y, static_cast<float>(slope * 15.0 + z), cls::kUnknown));
  const auto ground = markGround(scan, Pose::Identity(), GroundRemovalConfig{});
  size_t ground_hits = 0, object_hits = 0;
  for (size_t k = 0; k < scan.size(); ++k)
    (k < ground_points ? ground_hits : object_hits) += ground[k];
  EXPECT_GT(ground_hits, ground_points * 98 / 100);
  EXPECT_EQ(object_hits, 0u);
  // A fixed height threshold would have removed the box (it stands 2 m above the origin's ground).
  EXPECT_GT(slope * 15.0, 2.0);
}

// Asked only for the points no camera saw, it answers for them as it would for the whole scan:
// the classified points still give their cells' lowest returns.
TEST(GroundRemoval, OnlyUnobservedPointsAreAskedAndAnsweredAsInTheWholeScan) {
  EnrichedCloud scan;
  for (float x = -10; x <= 10; x += 0.25f)
    for (float y = -5; y <= 5; y += 0.25f) {
      // The road a camera saw at x < 0; beyond it the points have no class.
      scan.push_back(x < 0 ? point(x, y, 0.0f, cls::kRoad) : unobserved(x, y, 0.0f));
      if (std::fmod(x + 10.0f, 2.0f) == 0.0f) scan.push_back(unobserved(x, y, 1.5f));
    }
  const auto all = markGround(scan, Pose::Identity(), GroundRemovalConfig{});
  const auto asked = markGround(scan, Pose::Identity(), GroundRemovalConfig{}, true);
  size_t unobserved_ground = 0;
  for (size_t k = 0; k < scan.size(); ++k) {
    if (scan[k].has_class) {
      EXPECT_EQ(asked[k], 0) << k;
      EXPECT_EQ(all[k], 1) << k;
    } else {
      EXPECT_EQ(asked[k], all[k]) << k;
      unobserved_ground += asked[k];
    }
  }
  EXPECT_GT(unobserved_ground, 1000u);
}

// A point no camera saw is not of class unknown: it keeps its geometry, votes for no class, and
// its voxel takes the class of the frames in which a camera sees it (the front camera of a car
// sees a place before the LiDAR sweeps past it from the side).
TEST(LocalMap, UnobservedPointsKeepTheirGeometryAndTakeTheirClassFromLaterFrames) {
  LocalMap map = makeMap();
  const LocalMapUpdate u = map.update(
      {road(5.05f), unobserved(5.05f, 0.05f, 1.05f), point(8.05f, 0.05f, 1.05f, cls::kBuilding)},
      Pose::Identity(), {0, 0});
  EXPECT_EQ(u.points_inserted, 2u);
  EXPECT_EQ(u.points_unobserved, 1u);
  const VoxelKey seen_later = packVoxelKey({50, 0, 10});
  ASSERT_NE(map.find(seen_later), nullptr);
  EXPECT_TRUE(map.find(seen_later)->active);
  EXPECT_FALSE(map.find(seen_later)->hasClass());
  EXPECT_EQ(map.find(seen_later)->n_classified, 0u);
  map.update({road(5.05f), point(5.05f, 0.05f, 1.05f, cls::kFence)}, Pose::Identity(), {0, 0});
  EXPECT_TRUE(map.find(seen_later)->hasClass());
  EXPECT_EQ(map.find(seen_later)->semanticClass(), cls::kFence);
  // And it keeps that class when later frames see it unobserved again.
  map.update({road(5.05f), unobserved(5.05f, 0.05f, 1.05f), unobserved(5.05f, 0.05f, 1.05f)},
             Pose::Identity(), {0, 0});
  EXPECT_EQ(map.find(seen_later)->semanticClass(), cls::kFence);
  EXPECT_EQ(map.find(seen_later)->n_points, 4u);
}

// remove_unknown_class drops what the network called unknown, never what no camera saw; the
// paper's rig may still drop unobserved points of scans that have classes (remove_unobserved).
TEST(LocalMap, UnknownClassAndUnobservedAreFilteredByTheirOwnSettings) {
  EnrichedPoint network_unknown = point(5.05f, 0.05f, 1.05f, cls::kUnknown);
  const EnrichedCloud scan = {road(6.05f), network_unknown, unobserved(6.05f, 0.05f, 1.05f),
                              point(7.05f, 0.05f, 1.05f, cls::kBuilding)};
  LocalMap map = makeMap();
  EXPECT_EQ(map.update(scan, Pose::Identity(), {0, 0}).points_inserted, 2u);
  EXPECT_EQ(map.find(packVoxelKey({50, 0, 10})), nullptr);
  EXPECT_NE(map.find(packVoxelKey({60, 0, 10})), nullptr);
  LocalMapConfig paper;
  paper.remove_unobserved = true;
  LocalMap paper_map = makeMap(paper);
  EXPECT_EQ(paper_map.update(scan, Pose::Identity(), {0, 0}).points_inserted, 1u);
  // A scan without any class (no camera saw anything) is geometry-only even then.
  EXPECT_EQ(paper_map.update(groundAndWall(false), Pose::Identity(), {0, 0}).points_inserted,
            20u * 18u);
  LocalMapConfig keep_unknown;
  keep_unknown.remove_unknown_class = false;
  EXPECT_EQ(makeMap(keep_unknown).update(scan, Pose::Identity(), {0, 0}).points_inserted, 3u);
}

// Outside the picture the road has no class to be removed by: its ground goes geometrically,
// while labelled points are filtered by their class alone.
TEST(LocalMap, UnobservedGroundIsRemovedGeometrically) {
  LocalMap map = makeMap();
  const LocalMapUpdate u = map.update(groundAndWall(false), Pose::Identity(), {0, 0});
  EXPECT_EQ(u.points_unobserved, 3600u + 400u);
  // The ground and the wall's lowest 25 cm (the ground's tolerance) go; the rest of the wall stays.
  EXPECT_EQ(u.points_inserted, 20u * 18u);
  for (const auto& [key, v] : map.voxels()) EXPECT_GT(v.centroid.z(), 0.25f) << key;
  LocalMap labelled = makeMap();
  const LocalMapUpdate l = labelled.update(groundAndWall(true), Pose::Identity(), {0, 0});
  EXPECT_EQ(l.points_unobserved, 0u);
  EXPECT_EQ(l.points_inserted, 400u);  // the road by its class, the whole wall kept
}

// The dynamic share of a voxel is taken over the points that have a class: a car the camera saw
// in one frame and the LiDAR alone in three is still a car.
TEST(LocalMap, DynamicShareCountsOnlyPointsWithAClass) {
  EnrichedCloud scan = {road(5.05f)};
  for (int k = 0; k < 3; ++k) scan.push_back(unobserved(5.05f, 0.05f, 1.05f));
  scan.push_back(point(5.05f, 0.05f, 1.05f, cls::kCar));
  LocalMap map = makeMap();
  EXPECT_TRUE(map.update(scan, Pose::Identity(), {0, 0}).newly_active.empty());
  EXPECT_EQ(map.find(packVoxelKey({50, 0, 10}))->n_classified, 1u);
}
