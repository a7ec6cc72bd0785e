// Global relocalization from one scan (localize/relocalizer.h) on a synthetic town
// (synthetic_town.h) whose query descriptors are the map's with noise, so that the right target
// is among a local segment's 64 nearest but seldom its nearest: what a partial view's descriptor
// does.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "error_text.h"
#include "semsegmap/core/pose.h"
#include "semsegmap/core/random.h"
#include "semsegmap/localize/pose_covariance.h"
#include "semsegmap/localize/registration_check.h"
#include "semsegmap/localize/relocalizer.h"
#include "synthetic_town.h"

namespace semsegmap {
namespace {

TEST(RegistrationCheck, AcceptsThePosePointsLieOnAndRefusesAnother) {
  const Town town = makeTown(300, 300, 1);
  const Eigen::Vector3d robot(150, 150, 0);
  const Pose T = someLocalFrame();
  const Query q = queryAt(town, robot, T, 50, 0.0, 2);
  ASSERT_GE(q.points.size(), 5u);
  const RegistrationCheckConfig config;

  const RegistrationCheck right = checkRegistration(q.points, q.robot_local, town.map, T, config);
  EXPECT_TRUE(right.accepted) << right.reason;
  EXPECT_GT(right.fitness, 0.9) << right.correction_m << " m " << right.correction_deg << " deg";
  // The registration's planes come from 1.5 m voxels, and at the many corners of small
  // buildings they are bent: 9 cm off here (long facades do better).
  EXPECT_LT((right.T_map_local * q.robot_local - robot).norm(), 0.15);

  // Off by 0.6 m and 2 degrees: registration brings it back.
  const Pose off = Eigen::Translation3d(0.4, -0.45, 0.0) *
                   Eigen::AngleAxisd(2.0 * M_PI / 180, Eigen::Vector3d::UnitZ()) * T;
  const Pose off_robot = Eigen::Translation3d(T * q.robot_local - off * q.robot_local) * off;
  const RegistrationCheck near =
      checkRegistration(q.points, q.robot_local, town.map, off_robot, config);
  EXPECT_TRUE(near.accepted) << near.reason;
  EXPECT_LT((near.T_map_local * q.robot_local - T * q.robot_local).norm(), 0.1);

  // Another place of the town: the points do not lie on its walls.
  const Pose elsewhere = Eigen::Translation3d(120.0, -80.0, 0.0) * T;
  const RegistrationCheck wrong =
      checkRegistration(q.points, q.robot_local, town.map, elsewhere, config);
  EXPECT_FALSE(wrong.accepted);
  EXPECT_FALSE(wrong.reason.empty());
}

// A pose that tilts the local map against the map (both are level on a ground robot) is a
// symmetry's fit, however well the points lie: refused beyond check.max_tilt_deg.
TEST(RegistrationCheck, RefusesAPoseThatTiltsTheLocalMap) {
  const Town town = makeTown(300, 300, 1);
  const Eigen::Vector3d robot(150, 150, 0);
  const Pose tilted =
      someLocalFrame() * Eigen::AngleAxisd(20.0 * M_PI / 180, Eigen::Vector3d::UnitX());
  const Query q = queryAt(town, robot, tilted, 50, 0.0, 2);
  RegistrationCheckConfig config;
  const RegistrationCheck refused =
      checkRegistration(q.points, q.robot_local, town.map, tilted, config);
  EXPECT_FALSE(refused.accepted);
  EXPECT_GT(refused.fitness, 0.9) << "the points lie on the map's";
  EXPECT_EQ(refused.reason, "the pose tilts the local map against the map");
  config.max_tilt_deg = 25.0;
  const RegistrationCheck allowed =
      checkRegistration(q.points, q.robot_local, town.map, tilted, config);
  EXPECT_TRUE(allowed.accepted) << allowed.reason;
}

TEST(RegistrationCheck, RefusesTooFewPointsWithAReason) {
  const Town town = makeTown(50, 300, 3);
  const std::vector<Points> nothing(3);
  const RegistrationCheck r = checkRegistration(nothing, Eigen::Vector3d::Zero(), town.map,
                                                Pose::Identity(), RegistrationCheckConfig{});
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason, "too few points to register");
}

LocalizerConfig wholeMapLocalizer() {
  LocalizerConfig c;
  c.index.k = 16;
  return c;
}

// Noisy descriptors: the whole-map localizer (k = 16, six inliers) finds too few right matches,
// the places the 64 nearest vote for hold them, and the pose is the registered one.
TEST(Relocalizer, FindsTheRobotFromOneScanWhereTheWholeMapQueryDoesNot) {
  const Town town = makeTown(2000, 1000, 4);
  const Localizer localizer(town.map, wholeMapLocalizer());
  const Pose T = someLocalFrame();
  const RelocalizationConfig config;
  int relocalized = 0, whole_map = 0, tried = 0;
  for (double x : {200.0, 450.0, 650.0, 800.0})
    for (double y : {250.0, 550.0, 750.0}) {
      const Eigen::Vector3d robot(x, y, 0);
      const Query q = queryAt(town, robot, T, 45, 1.7, static_cast<uint64_t>(x + y));
      if (q.centroids.size() < 8) continue;
      ++tried;
      const auto l = localizer.localize(q.centroids, q.descriptors);
      whole_map += l && translationError(l->T_map_local, T) < 1.0;
      const auto r =
          relocalize(localizer, q.centroids, q.descriptors, q.points, q.robot_local, config);
      if (!r) continue;
      // Never wrong: a pose it gives is the registered one, and a town of random buildings has
      // no look-alike place.
      EXPECT_LT((r->match.T_map_local * q.robot_local - robot).norm(), 0.2);
      EXPECT_FALSE(r->ambiguous) << "runner-up " << r->runner_up_fitness << " against "
                                 << r->check.fitness;
      EXPECT_GE(r->check.fitness, config.check.min_fitness);
      ++relocalized;
    }
  ASSERT_GE(tried, 8);
  EXPECT_GE(relocalized, tried * 3 / 4) << "of " << tried;
  EXPECT_LE(2 * whole_map, relocalized) << "whole map " << whole_map << ", relocalized "
                                        << relocalized << ": the noise is meant to defeat "
                                        << "the whole-map query";
}

// The robot stands where the map has nothing like it: the map's segments near it were moved
// together to another place (so their descriptors and the layout of their centroids still
// match the query's: the verification finds a large clique there) and are other buildings there.
// Only the registration check can refuse it.
TEST(Relocalizer, RefusesAPlaceWhoseSegmentsMatchButWhosePointsDoNot) {
  Town town = makeTown(2000, 1000, 5);
  const Eigen::Vector3d robot(500, 500, 0);
  const Pose T = someLocalFrame();
  const Query q = queryAt(town, robot, T, 45, 0.3, 6);
  ASSERT_GE(q.centroids.size(), 8u);
  const Localizer before(town.map, wholeMapLocalizer());
  ASSERT_TRUE(relocalize(before, q.centroids, q.descriptors, q.points, q.robot_local, {}));

  SeededRng rng(11);
  size_t moved = 0;
  for (size_t i = 0; i < town.map.size(); ++i) {
    MapSegment& s = town.map.segments[i];
    if ((s.centroid.head<2>().cast<double>() - robot.head<2>()).norm() > 100) continue;
    Building other = town.buildings[i];
    other.centre += Eigen::Vector3f(700, 300, 0);
    other.size = Eigen::Vector3f(other.size.y() + 4, other.size.x() + 3, other.size.z());
    s.centroid += Eigen::Vector3f(700, 300, 0);
    s.points = wallsOf(other, rng, 0.5);
    ++moved;
  }
  ASSERT_GT(moved, 8u);
  const Localizer after(town.map, wholeMapLocalizer());
  const auto match = after.localize(q.centroids, q.descriptors);
  ASSERT_TRUE(match) << "the moved segments are meant to match as a whole";
  EXPECT_FALSE(relocalize(after, q.centroids, q.descriptors, q.points, q.robot_local, {}));
}

// A scan of one long wall: the registration pins the pose across the wall and leaves it free
// along it, and the covariance says so, large but finite along the wall.
TEST(RegistrationCheck, AScanOfOneWallIsUncertainAlongIt) {
  const Eigen::Vector3d along(std::cos(0.5), std::sin(0.5), 0), across(-along.y(), along.x(), 0);
  SeededRng rng(21);
  // The wall as eight segments of 5 m (the check takes a limited number of points a segment).
  auto wall = [&](double spacing_m) {
    std::vector<Points> out(8);
    for (double s = -20; s < 20; s += spacing_m)
      for (double z = 0; z <= 6; z += spacing_m)
        out[static_cast<size_t>((s + 20) / 5)].push_back(
            (s * along + Eigen::Vector3d(0, 0, z) + across * rng.gaussian(0.01)).cast<float>());
    return out;
  };
  TargetMap map;
  map.descriptor = "eigen";
  for (const Points& part : wall(0.25)) {
    MapSegment segment;
    segment.points = part;
    for (const Eigen::Vector3f& p : part) segment.centroid += p / static_cast<float>(part.size());
    segment.n_points = static_cast<uint32_t>(part.size());
    map.segments.push_back(segment);
  }
  map.descriptors = Eigen::MatrixXf::Zero(static_cast<Eigen::Index>(map.size()), 4);
  const Pose T = someLocalFrame();
  const Pose T_local_map = T.inverse();
  std::vector<Points> local;
  for (const Points& part : wall(0.3)) {
    local.emplace_back();
    for (const Eigen::Vector3f& p : part)
      local.back().push_back((T_local_map * p.cast<double>()).cast<float>());
  }
  const Eigen::Vector3d robot_map = 8.0 * across + Eigen::Vector3d(0, 0, 1.5);
  const RegistrationCheck c =
      checkRegistration(local, T_local_map * robot_map, map, T, RegistrationCheckConfig{});
  ASSERT_TRUE(c.accepted) << c.reason;
  const PoseCovarianceConfig config;
  const Covariance6 P =
      covarianceFromEvidence(c.evidence, robot_map, config.registration_inflation, config);
  ASSERT_TRUE(P.allFinite());
  const Eigen::Matrix3d position = P.topLeftCorner<3, 3>();
  const double sigma_along = std::sqrt(along.dot(position * along));
  const double sigma_across = std::sqrt(across.dot(position * across));
  EXPECT_GT(sigma_along, 10.0) << "across " << sigma_across;
  EXPECT_LE(sigma_along, config.max_sigma_m * 1.01);
  EXPECT_LT(sigma_across, 0.5);
  EXPECT_GE(sigma_across, config.min_sigma_m);
}

// A straight street of alike houses, every 16 m on both sides, alike descriptors: a scan in the
// middle registers as well one house further on. The relocalization gives no pose, or one marked
// ambiguous, never a plain one.
TEST(Relocalizer, AStraightStreetOfAlikeHousesGivesNoPoseOrAnAmbiguousOne) {
  Town street;
  SeededRng rng(31);
  street.map.descriptor = "eigen";
  std::vector<Eigen::VectorXf> rows;
  const Eigen::VectorXf house = Eigen::VectorXf::Constant(16, 1.0f);
  for (int i = 0; i < 40; ++i)
    for (const float side : {-12.0f, 12.0f}) {
      const Building b{Eigen::Vector3f(16.0f * static_cast<float>(i), side, 0),
                       Eigen::Vector3f(10, 8, 6)};
      street.buildings.push_back(b);
      MapSegment s;
      s.points = wallsOf(b, rng, 0.5);
      s.centroid = b.centre + Eigen::Vector3f(0, 0, 3);
      s.n_points = static_cast<uint32_t>(s.points.size());
      street.map.segments.push_back(s);
      rows.push_back(house);
    }
  street.map.descriptors.resize(static_cast<Eigen::Index>(rows.size()), 16);
  for (size_t i = 0; i < rows.size(); ++i)
    street.map.descriptors.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
  const Localizer localizer(street.map, wholeMapLocalizer());
  const Pose T = someLocalFrame();
  const Eigen::Vector3d robot(16.0 * 20 + 5, 0, 0);
  const Query q = queryAt(street, robot, T, 45, 0.05, 32);
  ASSERT_GE(q.centroids.size(), 8u);
  const auto r = relocalize(localizer, q.centroids, q.descriptors, q.points, q.robot_local,
                            RelocalizationConfig{});
  if (r) {
    EXPECT_TRUE(r->ambiguous) << "a pose " << (r->match.T_map_local * q.robot_local - robot).norm()
                              << " m from the robot, fitness " << r->check.fitness << ", runner-up "
                              << r->runner_up_fitness;
    EXPECT_GT(r->runner_up_fitness, 0.0);
  }
}

TEST(Relocalizer, APriorRestrictsThePlaces) {
  const Town town = makeTown(1000, 800, 7);
  const Localizer localizer(town.map, wholeMapLocalizer());
  const Eigen::Vector3d robot(400, 450, 0);
  const Pose T = someLocalFrame();
  const Query q = queryAt(town, robot, T, 45, 0.5, 8);
  ASSERT_GE(q.centroids.size(), 6u);
  RelocalizationPrior near{Eigen::Vector3d(390, 470, 0), 60};
  EXPECT_TRUE(relocalize(localizer, q.centroids, q.descriptors, q.points, q.robot_local,
                         RelocalizationConfig{}, near));
  RelocalizationPrior far{Eigen::Vector3d(200, 200, 0), 100};
  EXPECT_FALSE(relocalize(localizer, q.centroids, q.descriptors, q.points, q.robot_local,
                          RelocalizationConfig{}, far));
}

// A map holding one scan context; a scan whose bins are its columns turned by `shift` sectors
// (so the two lie `shift` sectors apart in yaw).
struct TurnedScan {
  TargetMap map;
  ScanContextQuery scan;
  Pose T_map_mapped =
      Eigen::Translation3d(100, 50, 0) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
};
TurnedScan turnedScan(int shift) {
  SeededRng rng(3);
  Eigen::MatrixXf bins(20, 60);
  for (Eigen::Index k = 0; k < bins.size(); ++k)
    bins(k) = rng.uniform(0, 1) < 0.3 ? 0.0f : static_cast<float>(rng.uniform(0.5, 12));
  TurnedScan t;
  t.map.scan_contexts.add(scanContextOfBins(bins), t.T_map_mapped);
  Eigen::MatrixXf turned(20, 60);
  for (Eigen::Index j = 0; j < 60; ++j) turned.col(j) = bins.col((j + shift) % 60);
  t.scan.context = scanContextOfBins(turned);
  t.scan.T_local_scan =
      Eigen::Translation3d(1, 2, 0) * Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ());
  return t;
}

// The map's scan context corroborates a pose that puts the scan near the mapped one at the yaw
// their columns say, and no other: turned 30 degrees more, or 20 m away.
TEST(Relocalizer, TheMapsScanContextsCorroborateOnlyAPoseThatAgreesWithThem) {
  const TurnedScan t = turnedScan(10);  // 60 degrees
  const RelocalizationConfig config;
  auto poseOf = [&](double yaw_deg, double ahead_m) {
    const Pose T_map_scan = t.T_map_mapped *
                            Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitZ()) *
                            Eigen::Translation3d(ahead_m, 0, 0);
    return Pose(T_map_scan * t.scan.T_local_scan.inverse());
  };
  EXPECT_TRUE(scanContextAgrees(t.map, t.scan, poseOf(60, 2), config));
  EXPECT_TRUE(scanContextAgrees(t.map, t.scan, poseOf(66, 2), config)) << "a sector off";
  EXPECT_FALSE(scanContextAgrees(t.map, t.scan, poseOf(90, 2), config));
  EXPECT_FALSE(scanContextAgrees(t.map, t.scan, poseOf(60, 20), config));
  // The same mapped scan contradicts a pose turned a quarter from the heading its context gives,
  // and says nothing of a pose where no mapped scan lies near.
  EXPECT_FALSE(headingContradicted(t.map, t.scan, poseOf(60, 2)));
  EXPECT_FALSE(headingContradicted(t.map, t.scan, poseOf(66, 2)));
  EXPECT_TRUE(headingContradicted(t.map, t.scan, poseOf(150, 2)));
  EXPECT_TRUE(headingContradicted(t.map, t.scan, poseOf(240, 2)));
  EXPECT_FALSE(headingContradicted(t.map, t.scan, poseOf(150, 20)));
  RegistrationCheck turned;
  turned.accepted = true;
  turned.T_map_local = poseOf(150, 2);
  refuseAContradictedHeading(turned, t.map, std::nullopt, config);
  EXPECT_TRUE(turned.accepted) << "without the scan's scan context nothing is refused";
  refuseAContradictedHeading(turned, t.map, t.scan, config);
  EXPECT_FALSE(turned.accepted);
  EXPECT_MENTIONS(turned.reason, "contradict its heading");

  // corroborate() lets such a pose pass with scan_context_min_fitness, not less, and only with the
  // scan's scan context.
  RegistrationCheck c;
  c.T_map_local = poseOf(60, 2);
  c.points = 1000;
  c.fitness = 0.5;
  c.reason = "the points do not lie on the map's";
  RegistrationCheck without = c;
  corroborate(without, t.map, std::nullopt, config);
  EXPECT_FALSE(without.accepted);
  RegistrationCheck low = c;
  low.fitness = config.scan_context_min_fitness - 0.05;
  corroborate(low, t.map, t.scan, config);
  EXPECT_FALSE(low.accepted);
  RegistrationCheck far = c;
  far.T_map_local = poseOf(90, 2);
  corroborate(far, t.map, t.scan, config);
  EXPECT_FALSE(far.accepted);
  corroborate(c, t.map, t.scan, config);
  EXPECT_TRUE(c.accepted);
  EXPECT_TRUE(c.reason.empty());
}

// A scan context cannot corroborate its own proposal. The robot stands where the map holds
// nothing; somewhere else half of its buildings stand as it sees them (with other descriptors,
// so the segments vote for nothing there), and the map's scan contexts along that street are the
// scan's own. That place registers at about half the points: below min_fitness, above what
// corroboration would accept. The scan context proposed it, so nothing may corroborate it but
// other evidence, and there is none: no pose.
TEST(Relocalizer, AScanContextsOwnWrongProposalBelowTheFitnessIsRefused) {
  Town town = makeTown(2000, 1000, 41);
  const Eigen::Vector3d robot(500, 500, 0);
  const Pose T = someLocalFrame();
  const Query q = queryAt(town, robot, T, 45, 0.3, 42);
  ASSERT_GE(q.centroids.size(), 8u);
  // The query's buildings, in its order (queryAt), copied until they hold 45 % of its points.
  size_t total = 0;
  for (const Points& p : q.points) total += p.size();
  std::vector<bool> copy(town.map.size(), false);
  size_t k = 0, copied_points = 0;
  for (size_t i = 0; i < town.buildings.size(); ++i) {
    if ((town.buildings[i].centre.head<2>().cast<double>() - robot.head<2>()).norm() > 45) continue;
    if (copied_points < total * 45 / 100) {
      copy[i] = true;
      copied_points += q.points[k].size();
    }
    ++k;
  }
  SeededRng rng(43);
  const Eigen::Vector3f offset(900, -700, 0);
  int copied = 0;
  for (size_t i = 0; i < town.map.size(); ++i) {
    MapSegment& s = town.map.segments[i];
    if ((s.centroid.head<2>().cast<double>() - robot.head<2>()).norm() > 100) continue;
    const Eigen::Vector3f to = copy[i] ? offset : Eigen::Vector3f(-3000, 4000, 0);
    s.centroid += to;
    for (Eigen::Vector3f& p : s.points) p += to;
    if (!copy[i]) continue;
    // Far from every query descriptor: never among a local segment's nearest, no vote.
    for (Eigen::Index d = 0; d < town.map.descriptors.cols(); ++d)
      town.map.descriptors(static_cast<Eigen::Index>(i), d) =
          100.0f + static_cast<float>(rng.gaussian(1));
    ++copied;
  }
  ASSERT_GE(copied, 4);
  const Pose wrong = Eigen::Translation3d(offset.cast<double>()) * T;
  // The scan context there is the scan's own, and so is one 30 m on: a straight road looks the
  // same along it, so neither is distinct (scan_context_distinct_ratio).
  const TurnedScan own = turnedScan(0);
  ScanContextQuery scan = own.scan;
  town.map.scan_contexts.add(own.scan.context, wrong * scan.T_local_scan);
  town.map.scan_contexts.add(own.scan.context,
                             Eigen::Translation3d(30, 0, 0) * wrong * scan.T_local_scan);
  const RelocalizationConfig config;
  // The place as the scan context proposes it: half on the map's points, corroborated by
  // itself.
  const RegistrationCheck there =
      checkRegistration(q.points, q.robot_local, town.map, wrong, config.check);
  ASSERT_FALSE(there.accepted);
  ASSERT_GE(there.fitness, config.scan_context_min_fitness) << there.reason;
  ASSERT_LT(there.fitness, config.check.min_fitness);
  ASSERT_TRUE(scanContextAgrees(town.map, scan, there.T_map_local, config));

  const Localizer localizer(town.map, wholeMapLocalizer());
  const auto r = relocalize(localizer, q.centroids, q.descriptors, q.points, q.robot_local, config,
                            std::nullopt, scan);
  EXPECT_FALSE(r) << "a pose " << (r->match.T_map_local * q.robot_local - robot).norm()
                  << " m from the robot, fitness " << r->check.fitness << " sc "
                  << r->by_scan_context << " d " << r->scan_context_distance << " rival "
                  << r->scan_context_rival;
}

// A localization farther from the held pose than jump_m, or turned more than jump_deg, is a jump
// (modes.cpp then asks the registration check for it): the world-5 VLP-32's local-map pose two
// scans after a right relocalization, 5.3 m and 15 degrees off, is one.
TEST(Relocalizer, APoseFarFromTheHeldOneIsAJump) {
  const RelocalizationConfig config;
  const Pose held =
      Eigen::Translation3d(10, 20, 0) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ());
  const auto moved = [&](double x, double yaw_deg) {
    return held * Eigen::Translation3d(x, 0, 0) *
           Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ());
  };
  EXPECT_FALSE(jumpsFrom(held, held, config));
  EXPECT_FALSE(jumpsFrom(held, moved(0.5 * config.jump_m, 0.5 * config.jump_deg), config));
  EXPECT_TRUE(jumpsFrom(held, moved(1.1 * config.jump_m, 0), config));
  EXPECT_TRUE(jumpsFrom(held, moved(0, 1.1 * config.jump_deg), config));
  EXPECT_TRUE(jumpsFrom(held, moved(5.3, 15.0), config));
}

TEST(Relocalizer, RefusesMismatchedInput) {
  const Town town = makeTown(20, 200, 9);
  const Localizer localizer(town.map, wholeMapLocalizer());
  const std::vector<Eigen::Vector3f> centroids(5, Eigen::Vector3f::Zero());
  EXPECT_THROW(relocalize(localizer, centroids, Eigen::MatrixXf::Zero(4, 16),
                          std::vector<Points>(5), Eigen::Vector3d::Zero(), {}),
               std::invalid_argument);
}

}  // namespace
}  // namespace semsegmap
