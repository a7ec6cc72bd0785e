// LiDAR odometry per scan on one core, and the registration of the libraries it was chosen
// against (docs/odometry.md): PCL's GICP, point-to-plane ICP and NDT, and Open3D's
// point-to-plane ICP and GICP when the build found Open3D. Input: the ten real KITTI 00 scans of
// ../shared/data (HDL-64E, ~124k points each). Each benchmark registers scans 1-9 one after the
// other (the libraries scan to scan, from a constant-velocity guess; ours scan to its local
// map) and reports the mean frame-to-frame error against the ground truth as counters
// (t_err_m, r_err_deg); items per second are scans per second. Run it on one core:
//   taskset -c 0 build/bench/semsegmap_bench --benchmark_filter=Odometry
// Target: >= 20 scans/s.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <pcl/features/normal_3d.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/ndt.h>
#if SEMSEGMAP_BENCH_OPEN3D
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/GeneralizedICP.h>
#include <open3d/pipelines/registration/Registration.h>
#endif

#include "semsegmap/io/kitti_calib.h"
#include "semsegmap/odometry/lidar_odometry.h"

using namespace semsegmap;

namespace {

const std::filesystem::path kKitti =
    std::filesystem::path(SEMSEGMAP_SOURCE_DIR) / ".." / "shared" / "data" / "kitti00_first10_pcd";

struct KittiScans {
  std::vector<pcl::PointCloud<pcl::PointXYZ>::Ptr> clouds;
  std::vector<Pose> gt;  // LiDAR poses: Tr^-1 * P_i * Tr
};

// The scans once; empty when ../shared/data is not beside the checkout.
const KittiScans& kitti() {
  static const KittiScans scans = [] {
    KittiScans s;
    if (!std::filesystem::exists(kKitti / "poses.txt")) return s;
    const Pose Tr = KittiCalibFile(kKitti / "calib.txt").transform3x4("Tr");
    s.gt = kittiLidarPoses(readKittiPoses(kKitti / "poses.txt"), Tr);
    for (int i = 0; i < 10; ++i) {
      char name[16];
      std::snprintf(name, sizeof(name), "%06d.pcd", i);
      s.clouds.emplace_back(new pcl::PointCloud<pcl::PointXYZ>);
      pcl::io::loadPCDFile((kKitti / name).string(), *s.clouds.back());
    }
    return s;
  }();
  return scans;
}

// Mean frame-to-frame error of the estimated motions against the ground truth's, as counters.
void reportAccuracy(benchmark::State& state, const std::vector<Pose>& motions) {
  const KittiScans& k = kitti();
  double t = 0, r = 0;
  for (size_t i = 0; i < motions.size(); ++i) {
    const Pose truth = k.gt[i].inverse() * k.gt[i + 1];
    t += translationError(motions[i], truth);
    r += rotationErrorDeg(motions[i], truth);
  }
  state.counters["t_err_m"] = t / static_cast<double>(motions.size());
  state.counters["r_err_deg"] = r / static_cast<double>(motions.size());
}

bool haveScans(benchmark::State& state) {
  omp_set_num_threads(1);  // one core, whatever the library would use
  if (!kitti().clouds.empty()) return true;
  state.SkipWithError("no ../shared/data/kitti00_first10_pcd beside the checkout");
  return false;
}

void BM_OdometryOurs(benchmark::State& state) {
  if (!haveScans(state)) return;
  std::vector<std::vector<LidarPoint>> scans;
  for (const auto& cloud : kitti().clouds) {
    scans.emplace_back();
    for (const auto& p : cloud->points) scans.back().push_back({p.x, p.y, p.z, 0.0f});
  }
  std::vector<Pose> motions;
  for (auto _ : state) {
    LidarOdometry odometry;
    std::vector<Pose> poses;
    for (size_t i = 0; i < scans.size(); ++i)
      poses.push_back(odometry.registerFrame(scans[i], {}, 0.1 * i).T_odom_lidar);
    motions.clear();
    for (size_t i = 1; i < poses.size(); ++i) motions.push_back(poses[i - 1].inverse() * poses[i]);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(scans.size()));
  reportAccuracy(state, motions);
}
BENCHMARK(BM_OdometryOurs)->Unit(benchmark::kMillisecond);

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

Cloud::Ptr downsample(const Cloud::Ptr& cloud, float leaf) {
  Cloud::Ptr out(new Cloud);
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(cloud);
  grid.setLeafSize(leaf, leaf, leaf);
  grid.filter(*out);
  return out;
}

// One scan-to-scan registration: target, source, initial guess -> source-to-target transform.
using Register =
    std::function<Eigen::Matrix4f(const Cloud::Ptr&, const Cloud::Ptr&, const Eigen::Matrix4f&)>;

// Scans 1-9 registered to the scan before, each guess the motion before (constant velocity);
// the downsampling of every scan (0.5 m) is part of the time.
void runScanToScan(benchmark::State& state, const Register& align) {
  if (!haveScans(state)) return;
  std::vector<Pose> motions;
  for (auto _ : state) {
    motions.clear();
    Eigen::Matrix4f guess = Eigen::Matrix4f::Identity();
    Cloud::Ptr target = downsample(kitti().clouds[0], 0.5f);
    for (size_t i = 1; i < kitti().clouds.size(); ++i) {
      Cloud::Ptr source = downsample(kitti().clouds[i], 0.5f);
      guess = align(target, source, guess);
      Pose T;
      T.matrix() = guess.cast<double>();
      motions.push_back(T);
      target = source;
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(kitti().clouds.size() - 1));
  reportAccuracy(state, motions);
}

void BM_OdometryPclGicp(benchmark::State& state) {
  runScanToScan(
      state, [](const Cloud::Ptr& target, const Cloud::Ptr& source, const Eigen::Matrix4f& guess) {
        pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
        gicp.setInputTarget(target);
        gicp.setInputSource(source);
        gicp.setMaxCorrespondenceDistance(1.0);
        gicp.setMaximumIterations(30);
        Cloud out;
        gicp.align(out, guess);
        return gicp.getFinalTransformation();
      });
}
BENCHMARK(BM_OdometryPclGicp)->Unit(benchmark::kMillisecond);

pcl::PointCloud<pcl::PointNormal>::Ptr withNormals(const Cloud::Ptr& cloud) {
  pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
  pcl::PointCloud<pcl::Normal> normals;
  estimation.setInputCloud(cloud);
  estimation.setRadiusSearch(1.0);
  estimation.compute(normals);
  pcl::PointCloud<pcl::PointNormal>::Ptr out(new pcl::PointCloud<pcl::PointNormal>);
  pcl::concatenateFields(*cloud, normals, *out);
  // Points without a normal (too few neighbours) would poison the point-to-plane system.
  pcl::PointCloud<pcl::PointNormal>::Ptr finite(new pcl::PointCloud<pcl::PointNormal>);
  for (const auto& p : out->points)
    if (std::isfinite(p.normal_x)) finite->push_back(p);
  return finite;
}

void BM_OdometryPclIcpPointToPlane(benchmark::State& state) {
  runScanToScan(
      state, [](const Cloud::Ptr& target, const Cloud::Ptr& source, const Eigen::Matrix4f& guess) {
        pcl::IterativeClosestPointWithNormals<pcl::PointNormal, pcl::PointNormal> icp;
        icp.setInputTarget(withNormals(target));
        icp.setInputSource(withNormals(source));
        icp.setMaxCorrespondenceDistance(1.0);
        icp.setMaximumIterations(30);
        pcl::PointCloud<pcl::PointNormal> out;
        icp.align(out, guess);
        return icp.getFinalTransformation();
      });
}
BENCHMARK(BM_OdometryPclIcpPointToPlane)->Unit(benchmark::kMillisecond);

void BM_OdometryPclNdt(benchmark::State& state) {
  runScanToScan(
      state, [](const Cloud::Ptr& target, const Cloud::Ptr& source, const Eigen::Matrix4f& guess) {
        pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> ndt;
        ndt.setResolution(1.0f);
        ndt.setStepSize(0.1);
        ndt.setTransformationEpsilon(0.01);
        ndt.setMaximumIterations(30);
        ndt.setInputTarget(target);
        ndt.setInputSource(source);
        Cloud out;
        ndt.align(out, guess);
        return ndt.getFinalTransformation();
      });
}
BENCHMARK(BM_OdometryPclNdt)->Unit(benchmark::kMillisecond);

#if SEMSEGMAP_BENCH_OPEN3D
std::shared_ptr<open3d::geometry::PointCloud> toOpen3d(const Cloud::Ptr& cloud, bool normals) {
  auto out = std::make_shared<open3d::geometry::PointCloud>();
  for (const auto& p : cloud->points) out->points_.emplace_back(p.x, p.y, p.z);
  if (normals) out->EstimateNormals(open3d::geometry::KDTreeSearchParamHybrid(1.0, 30));
  return out;
}

void runOpen3d(benchmark::State& state, bool gicp) {
  namespace reg = open3d::pipelines::registration;
  runScanToScan(state, [gicp](const Cloud::Ptr& target, const Cloud::Ptr& source,
                              const Eigen::Matrix4f& guess) {
    const auto t = toOpen3d(target, !gicp), s = toOpen3d(source, !gicp);
    const reg::ICPConvergenceCriteria criteria(1e-6, 1e-6, 30);
    const reg::RegistrationResult r =
        gicp ? reg::RegistrationGeneralizedICP(*s, *t, 1.0, guess.cast<double>(),
                                               reg::TransformationEstimationForGeneralizedICP(),
                                               criteria)
             : reg::RegistrationICP(*s, *t, 1.0, guess.cast<double>(),
                                    reg::TransformationEstimationPointToPlane(), criteria);
    return Eigen::Matrix4f(r.transformation_.cast<float>());
  });
}

void BM_OdometryOpen3dIcpPointToPlane(benchmark::State& state) {
  runOpen3d(state, false);
}
BENCHMARK(BM_OdometryOpen3dIcpPointToPlane)->Unit(benchmark::kMillisecond);
void BM_OdometryOpen3dGicp(benchmark::State& state) {
  runOpen3d(state, true);
}
BENCHMARK(BM_OdometryOpen3dGicp)->Unit(benchmark::kMillisecond);
#endif

}  // namespace
