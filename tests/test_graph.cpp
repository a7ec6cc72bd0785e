// The loop-closure pose graph removes drift and shrugs off a wrong loop closure; trajectory files
// read back as written and malformed ones name the offending line; the trajectory error is right.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "semsegmap/graph/pose_graph.h"
#include "semsegmap/graph/trajectory.h"
#include "semsegmap/io/trajectory_file.h"
#include "temp_dir.h"

namespace semsegmap {
namespace {
namespace fs = std::filesystem;

constexpr double kDeg = M_PI / 180.0;

using semsegmap::test_support::TempDir;

// A circle of 200 poses 1 m apart (with a gentle up and down) that ends 1 m before the start.
std::vector<Pose> circleTrajectory(int n = 200) {
  const double radius = n / (2.0 * M_PI);
  std::vector<Pose> poses;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * M_PI * i / n;
    poses.push_back(
        planarPose(radius * std::sin(a), radius * (1.0 - std::cos(a)), 0.5 * std::sin(2 * a), a));
  }
  return poses;
}

// Odometry with 1 % scale error, 0.05 deg/m of yaw drift and a little white noise.
std::vector<Pose> driftingOdometry(const std::vector<Pose>& truth) {
  std::mt19937 rng(7);
  std::normal_distribution<double> translation_noise(0.0, 0.002), rotation_noise(0.0, 0.0003);
  std::vector<Pose> odometry;
  for (size_t i = 0; i + 1 < truth.size(); ++i) {
    Pose rel = truth[i].inverse() * truth[i + 1];
    const double length = rel.translation().norm();
    rel.translation() *= 1.01;
    const Eigen::Vector3d noise_t(translation_noise(rng), translation_noise(rng),
                                  translation_noise(rng));
    const Eigen::Vector3d noise_r(rotation_noise(rng), rotation_noise(rng), rotation_noise(rng));
    rel.translation() += noise_t;
    rel.linear() = rel.linear() *
                   Eigen::AngleAxisd(0.05 * kDeg * length, Eigen::Vector3d::UnitZ()).matrix() *
                   Eigen::AngleAxisd(noise_r.norm(), noise_r.normalized()).matrix();
    odometry.push_back(rel);
  }
  return odometry;
}

struct Loop {
  size_t from, to;
  Pose T_from_to;
};

// Nodes initialised by composing the odometry from the true first pose, as a SLAM front end does.
PoseGraph buildGraph(const std::vector<Pose>& truth, const std::vector<Loop>& loops,
                     const PoseGraphConfig& config = {}) {
  const std::vector<Pose> odometry = driftingOdometry(truth);
  PoseGraph graph(config);
  Pose current = truth.front();
  graph.addNode(current);
  for (size_t i = 0; i < odometry.size(); ++i) {
    current = current * odometry[i];
    graph.addNode(current);
    graph.addOdometry(i, i + 1, odometry[i]);
  }
  for (const Loop& l : loops) graph.addLoop(l.from, l.to, l.T_from_to);
  return graph;
}

// The last few nodes recognise the first few places.
std::vector<Loop> correctLoops(const std::vector<Pose>& truth) {
  std::vector<Loop> loops;
  const size_t last = truth.size() - 1;
  for (size_t k = 0; k < 4; ++k) {
    const size_t from = 2 * k, to = last - k;
    loops.push_back({from, to, truth[from].inverse() * truth[to]});
  }
  return loops;
}

std::vector<Pose> nodePoses(const PoseGraph& graph) {
  std::vector<Pose> poses;
  for (size_t i = 0; i < graph.size(); ++i) poses.push_back(graph.pose(i));
  return poses;
}

double unalignedAte(const PoseGraph& graph, const std::vector<Pose>& truth) {
  return absoluteTrajectoryError(nodePoses(graph), truth, false).rmse_m;
}

TEST(PoseGraph, LoopClosureRemovesInjectedDrift) {
  const std::vector<Pose> truth = circleTrajectory();
  PoseGraph graph = buildGraph(truth, correctLoops(truth));
  const TrajectoryError before = absoluteTrajectoryError(nodePoses(graph), truth, false);
  const double end_error_before = translationError(graph.pose(graph.size() - 1), truth.back());

  const PoseGraph::Summary summary = graph.optimize();
  const TrajectoryError after = absoluteTrajectoryError(nodePoses(graph), truth, false);
  std::printf("drift: ATE before %.3f m (end %.3f m), after %.3f m, max %.3f m, %d iterations\n",
              before.rmse_m, end_error_before, after.rmse_m, after.max_m, summary.iterations);

  EXPECT_GT(end_error_before, 3.0) << "the injected drift should be several metres at the end";
  EXPECT_TRUE(summary.converged);
  EXPECT_EQ(summary.loops, 4u);
  EXPECT_LT(summary.final_cost, summary.initial_cost);
  EXPECT_LT(after.rmse_m * 5.0, before.rmse_m);
  EXPECT_LT(after.rmse_m, 0.5);
  EXPECT_LT(translationError(graph.pose(graph.size() - 1), truth.back()), 0.3);
  // What remains is the 1 % scale error, which no loop closure on a closed loop can observe (a
  // scaled loop is still closed): against the truth scaled by 1.01 about node 0, it is small.
  std::vector<Pose> scaled_truth = truth;
  for (Pose& p : scaled_truth)
    p.translation() = truth[0].translation() + 1.01 * (p.translation() - truth[0].translation());
  const double after_scaled = absoluteTrajectoryError(nodePoses(graph), scaled_truth, false).rmse_m;
  std::printf("drift: ATE after against the 1.01-scaled truth %.3f m\n", after_scaled);
  EXPECT_LT(after_scaled, 0.1);
  EXPECT_TRUE(graph.pose(0).isApprox(truth.front(), 1e-12)) << "node 0 fixes the gauge";
}

TEST(PoseGraph, WrongLoopClosureIsIgnoredThanksToRobustLoss) {
  const std::vector<Pose> truth = circleTrajectory();
  std::vector<Loop> loops = correctLoops(truth);
  // A false place recognition across the circle, 20 m off the truth.
  Pose wrong = truth[60].inverse() * truth[150];
  wrong.translation() += Eigen::Vector3d(20.0, 0.0, 0.0);
  std::vector<Loop> loops_with_wrong = loops;
  loops_with_wrong.push_back({60, 150, wrong});

  PoseGraph clean = buildGraph(truth, loops);
  PoseGraph robust = buildGraph(truth, loops_with_wrong);
  PoseGraphConfig no_robust_config;
  no_robust_config.loop_robust_scale = 0.0;
  PoseGraph not_robust = buildGraph(truth, loops_with_wrong, no_robust_config);
  clean.optimize();
  robust.optimize();
  not_robust.optimize();

  const double ate_clean = unalignedAte(clean, truth);
  const double ate_robust = unalignedAte(robust, truth);
  const double ate_not_robust = unalignedAte(not_robust, truth);
  std::printf("wrong loop: ATE clean %.3f m, robust %.3f m, without robust loss %.3f m\n",
              ate_clean, ate_robust, ate_not_robust);
  EXPECT_LT(ate_robust, 1.5 * ate_clean + 0.05);
  // Otherwise the wrong edge would not be a test of anything.
  EXPECT_GT(ate_not_robust, 3.0 * ate_robust + 1.0);
}

TEST(PoseGraph, WithoutLoopsOptimizeKeepsTheOdometryChain) {
  const std::vector<Pose> truth = circleTrajectory();
  PoseGraph graph = buildGraph(truth, {});
  const std::vector<Pose> initial = nodePoses(graph);
  const PoseGraph::Summary summary = graph.optimize();
  EXPECT_EQ(summary.loops, 0u);
  EXPECT_LT(summary.final_cost, 1e-12);
  for (size_t i = 0; i < graph.size(); ++i) {
    EXPECT_LT(translationError(graph.pose(i), initial[i]), 1e-6) << "node " << i;
    EXPECT_LT(rotationErrorDeg(graph.pose(i), initial[i]), 1e-6) << "node " << i;
  }
}

TEST(PoseGraph, RejectsBadEdgesAndConfig) {
  PoseGraph graph;
  graph.addNode(Pose::Identity());
  graph.addNode(Pose::Identity());
  EXPECT_THROW(graph.addOdometry(0, 2, Pose::Identity()), std::out_of_range);
  EXPECT_THROW(graph.addLoop(1, 1, Pose::Identity()), std::invalid_argument);
  Pose nan_pose = Pose::Identity();
  nan_pose.translation().x() = std::nan("");
  EXPECT_THROW(graph.addLoop(0, 1, nan_pose), std::invalid_argument);
  EXPECT_TRUE(graph.edges().empty());
  PoseGraphConfig bad;
  bad.loop_translation_sigma_m = 0.0;
  EXPECT_THROW(PoseGraph{bad}, std::invalid_argument);
}

std::vector<StampedPose> randomStampedPoses(int n) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-100.0, 100.0);
  std::vector<StampedPose> poses;
  for (int i = 0; i < n; ++i) {
    StampedPose p;
    p.timestamp_s = 1317384506.123456789 + 0.1 * i;
    p.T = Pose::Identity();
    p.T.linear() = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
    p.T.translation() = Eigen::Vector3d(u(rng), u(rng), u(rng));
    poses.push_back(p);
  }
  return poses;
}

TEST(Trajectory, TumRoundTripIsExactToPrintedPrecision) {
  TempDir tmp;
  const std::vector<StampedPose> written = randomStampedPoses(50);
  const fs::path file = tmp.path() / "traj.tum";
  writeTum(file, written);
  const std::vector<StampedPose> read = readTum(file);
  ASSERT_EQ(read.size(), written.size());
  for (size_t i = 0; i < read.size(); ++i) {
    // 9 decimals is more than a double holds at 1e9 s, so the timestamp comes back bit-exact.
    EXPECT_EQ(read[i].timestamp_s, written[i].timestamp_s);
    EXPECT_LE((read[i].T.translation() - written[i].T.translation()).cwiseAbs().maxCoeff(),
              5.01e-10);
    EXPECT_LE((read[i].T.linear() - written[i].T.linear()).cwiseAbs().maxCoeff(), 3e-9);
  }
  for (const auto& entry : fs::directory_iterator(tmp.path()))
    EXPECT_EQ(entry.path().filename(), "traj.tum") << "no temporary file left behind";
}

TEST(Trajectory, KittiLinesHoldTheTwelveMatrixNumbers) {
  TempDir tmp;
  const std::vector<StampedPose> written = randomStampedPoses(20);
  const fs::path file = tmp.path() / "poses.txt";
  writeKitti(file, written);
  std::ifstream in(file);
  std::string line;
  size_t row = 0;
  while (std::getline(in, line)) {
    ASSERT_LT(row, written.size());
    std::istringstream fields(line);
    std::vector<double> values;
    double v;
    while (fields >> v) values.push_back(v);
    ASSERT_EQ(values.size(), 12u) << line;
    const Eigen::Matrix4d m = written[row].T.matrix();
    for (int k = 0; k < 12; ++k) {
      const double expected = m(k / 4, k % 4);
      EXPECT_NEAR(values[k], expected, 1e-9 * std::max(1.0, std::abs(expected))) << "line " << row;
    }
    ++row;
  }
  EXPECT_EQ(row, written.size());
}

std::string readTumError(const fs::path& file, const std::string& text) {
  std::ofstream(file) << text;
  try {
    readTum(file);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Trajectory, MalformedTumLinesNameFileAndLine) {
  TempDir tmp;
  const fs::path file = tmp.path() / "bad.tum";
  const std::string good = "# timestamp x y z qx qy qz qw\n0.0 1 2 3 0 0 0 1\n\n";
  const std::string prefix = file.string() + ":4: ";
  EXPECT_EQ(readTumError(file, good + "0.1 1 2 3 0 0 abc 1\n").rfind(prefix, 0), 0u);
  EXPECT_EQ(readTumError(file, good + "0.1 1 2 3 0 0 1\n").rfind(prefix, 0), 0u);
  EXPECT_EQ(readTumError(file, good + "0.1 1 nan 3 0 0 0 1\n").rfind(prefix, 0), 0u);
  EXPECT_EQ(readTumError(file, good + "0.1 1 2 3 0 0 0 2\n").rfind(prefix, 0), 0u);
  EXPECT_NE(readTumError(file, good + "0.1 1 2 3 0 0 abc 1\n").find("abc"), std::string::npos);

  // Close to unit (few printed decimals) is normalised; CRLF line ends are accepted.
  std::ofstream(file) << good << "0.1 1 2 3 0.7071 0 0 0.7071\r\n";
  const std::vector<StampedPose> poses = readTum(file);
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_NEAR(poses[1].timestamp_s, 0.1, 1e-15);
  EXPECT_NEAR(yawOf(poses[1].T), 0.0, 1e-12);
  EXPECT_NEAR(rotationErrorDeg(poses[1].T, Pose::Identity()), 90.0, 1e-9);
  EXPECT_NEAR(poses[1].T.linear().determinant(), 1.0, 1e-12);
}

TEST(Trajectory, AteOfKnownOffsets) {
  const std::vector<Pose> truth = circleTrajectory(40);
  std::vector<Pose> estimate;
  for (size_t i = 0; i < truth.size(); ++i) {
    Pose p = truth[i];
    p.translation() += i % 2 == 0 ? Eigen::Vector3d(0.3, 0, 0) : Eigen::Vector3d(0, 0.4, 0);
    p.linear() = p.linear() * Eigen::AngleAxisd(2.0 * kDeg, Eigen::Vector3d::UnitX()).matrix();
    estimate.push_back(p);
  }
  const TrajectoryError e = absoluteTrajectoryError(estimate, truth, false);
  EXPECT_EQ(e.n, truth.size());
  EXPECT_NEAR(e.rmse_m, std::sqrt((0.09 + 0.16) / 2.0), 1e-12);
  EXPECT_NEAR(e.mean_m, 0.35, 1e-12);
  EXPECT_NEAR(e.max_m, 0.4, 1e-12);
  EXPECT_NEAR(e.rotation_mean_deg, 2.0, 1e-9);
  EXPECT_THROW(absoluteTrajectoryError(estimate, {truth.begin(), truth.end() - 1}, false),
               std::invalid_argument);
  EXPECT_THROW(absoluteTrajectoryError({}, {}, true), std::invalid_argument);
}

TEST(Trajectory, AlignedAteOfARigidlyMovedCopyIsZero) {
  const std::vector<Pose> truth = circleTrajectory(60);
  Pose T_moved = Pose::Identity();
  T_moved.linear() = Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  T_moved.translation() = Eigen::Vector3d(15.0, -40.0, 7.0);
  std::vector<Pose> estimate;
  for (const Pose& p : truth) estimate.push_back(T_moved * p);
  EXPECT_GT(absoluteTrajectoryError(estimate, truth, false).rmse_m, 10.0);
  const TrajectoryError aligned = absoluteTrajectoryError(estimate, truth, true);
  EXPECT_LT(aligned.rmse_m, 1e-9);
  EXPECT_LT(aligned.max_m, 1e-9);
  EXPECT_LT(aligned.rotation_mean_deg, 1e-6);
}

}  // namespace
}  // namespace semsegmap
