#include "semsegmap/describe/fpfh_descriptor.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <numeric>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <omp.h>
#include <pcl/features/fpfh.h>
#include <pcl/features/normal_3d.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <Eigen/Eigenvalues>

namespace semsegmap {

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Normals = pcl::PointCloud<pcl::Normal>;

// At most max_points indices, evenly spaced in the ranking by distance to the centroid (ties
// broken by coordinates). Unlike a stride over the input or a voxel grid, this choice does not
// depend on the order of the points, nor (but for rounding in near ties) on a rotation or
// translation of the segment; and it keeps the radial distribution, which is what the centroid's
// FPFH weighs by.
pcl::IndicesPtr radialSubsample(const Cloud& centred, int max_points) {
  const int n = static_cast<int>(centred.size());
  auto indices = std::make_shared<pcl::Indices>(n);
  std::iota(indices->begin(), indices->end(), 0);
  if (n <= max_points) return indices;
  using Key = std::tuple<float, float, float, float, int>;  // distance^2, x, y, z, index
  std::vector<Key> keys(n);
  for (int i = 0; i < n; ++i) {
    const pcl::PointXYZ& p = centred[i];
    keys[i] = {p.getVector3fMap().squaredNorm(), p.x, p.y, p.z, i};
  }
  std::sort(keys.begin(), keys.end());
  indices->resize(max_points);
  for (int i = 0; i < max_points; ++i) {
    const int64_t rank = static_cast<int64_t>(2 * i + 1) * n / (2 * max_points);
    (*indices)[i] = std::get<4>(keys[rank]);
  }
  return indices;
}

// The least-variance axis, signed so that the third moment along it is not negative: a
// direction that moves with the segment under any rigid motion.
Eigen::Vector3f leastVarianceAxis(const Cloud& centred) {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const pcl::PointXYZ& p : centred) {
    const Eigen::Vector3d d = p.getVector3fMap().cast<double>();
    cov.noalias() += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  Eigen::Vector3d axis = solver.eigenvectors().col(0);
  double third_moment = 0.0;
  for (const pcl::PointXYZ& p : centred)
    third_moment += std::pow(p.getVector3fMap().cast<double>().dot(axis), 3);
  if (third_moment < 0.0) axis = -axis;
  return axis.cast<float>();
}

void validate(const FpfhConfig& config) {
  if (config.normal_k < 3)
    throw std::invalid_argument("FpfhConfig.normal_k: expected at least 3, got " +
                                std::to_string(config.normal_k));
  if (config.max_points < 3)
    throw std::invalid_argument("FpfhConfig.max_points: expected at least 3, got " +
                                std::to_string(config.max_points));
  if (!(config.radius_margin_m >= 0.0) || !std::isfinite(config.radius_margin_m))
    throw std::invalid_argument("FpfhConfig.radius_margin_m: expected a finite value >= 0, got " +
                                std::to_string(config.radius_margin_m));
  if (!std::isfinite(config.normal_viewpoint_offset_m))
    throw std::invalid_argument("FpfhConfig.normal_viewpoint_offset_m: expected a finite value");
  if (config.threads < 0)
    throw std::invalid_argument("FpfhConfig.threads: expected >= 0, got " +
                                std::to_string(config.threads));
}

}  // namespace

Eigen::Matrix<float, kFpfhDimension, 1> fpfhFeatures(const EnrichedCloud& points,
                                                     const FpfhConfig& config) {
  validate(config);
  Eigen::Matrix<float, kFpfhDimension, 1> result = Eigen::Matrix<float, kFpfhDimension, 1>::Zero();
  if (points.size() < 3) return result;

  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const EnrichedPoint& p : points) centroid += Eigen::Vector3d(p.x, p.y, p.z);
  centroid /= static_cast<double>(points.size());
  if (!centroid.allFinite())
    throw std::invalid_argument("fpfhFeatures: a point has a non-finite coordinate");

  // Centred on the centroid: float precision is spent on the segment's shape, not on its
  // distance from the map origin, and the keypoint is the origin.
  auto full = std::make_shared<Cloud>();
  full->reserve(points.size());
  float max_dist2 = 0.0f;
  for (const EnrichedPoint& p : points) {
    const Eigen::Vector3f d = (Eigen::Vector3d(p.x, p.y, p.z) - centroid).cast<float>();
    full->push_back(pcl::PointXYZ(d.x(), d.y(), d.z()));
    max_dist2 = std::max(max_dist2, d.squaredNorm());
  }
  full->is_dense = true;

  const Eigen::Vector3f viewpoint =
      static_cast<float>(config.normal_viewpoint_offset_m) * leastVarianceAxis(*full);
  const pcl::IndicesPtr kept = radialSubsample(*full, config.max_points);

  // Normals of the kept points from their neighbours among all points.
  Normals kept_normals;
  {
    pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
    estimation.setInputCloud(full);
    estimation.setIndices(kept);
    estimation.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>(false));
    estimation.setKSearch(std::min(config.normal_k, static_cast<int>(full->size())));
    estimation.setViewPoint(viewpoint.x(), viewpoint.y(), viewpoint.z());
    estimation.compute(kept_normals);
  }

  // PCL's pair features turn a NaN normal into an out-of-range histogram index: leave out the
  // points whose neighbourhood gave none.
  auto surface = std::make_shared<Cloud>();
  auto normals = std::make_shared<Normals>();
  for (size_t i = 0; i < kept->size(); ++i) {
    const pcl::Normal& nrm = kept_normals[i];
    if (!std::isfinite(nrm.normal_x) || !std::isfinite(nrm.normal_y) ||
        !std::isfinite(nrm.normal_z))
      continue;
    surface->push_back((*full)[(*kept)[i]]);
    normals->push_back(nrm);
  }
  if (surface->size() < 2) return result;
  surface->is_dense = true;

  auto keypoint = std::make_shared<Cloud>();
  keypoint->push_back(pcl::PointXYZ(0.0f, 0.0f, 0.0f));
  keypoint->is_dense = true;

  pcl::FPFHEstimation<pcl::PointXYZ, pcl::Normal, pcl::FPFHSignature33> fpfh;
  fpfh.setInputCloud(keypoint);
  fpfh.setSearchSurface(surface);
  fpfh.setInputNormals(normals);
  fpfh.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>(false));
  fpfh.setRadiusSearch(std::sqrt(max_dist2) + config.radius_margin_m);
  pcl::PointCloud<pcl::FPFHSignature33> out;
  fpfh.compute(out);
  if (out.size() != 1) return result;

  for (int i = 0; i < kFpfhDimension; ++i) result(i) = out[0].histogram[i] / 100.0f;
  if (!result.allFinite()) result.setZero();
  return result;
}

FpfhDescriber::FpfhDescriber(const FpfhConfig& config) : config_(config) {
  validate(config);
}

Eigen::MatrixXf FpfhDescriber::describe(const std::vector<DescriptorInput>& batch) {
  for (size_t i = 0; i < batch.size(); ++i)
    if (batch[i].points == nullptr)
      throw std::invalid_argument("FpfhDescriber::describe: input " + std::to_string(i) +
                                  " of the batch has no point cloud (null pointer)");

  const int n = static_cast<int>(batch.size());
  Eigen::MatrixXf out(n, kFpfhDimension);
  // An exception must not leave an OpenMP region: keep the first and rethrow it afterwards.
  std::exception_ptr error;
  const int threads = config_.threads > 0 ? config_.threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic) num_threads(threads)
  for (int i = 0; i < n; ++i) {
    try {
      out.row(i) = fpfhFeatures(*batch[i].points, config_).transpose();
    } catch (...) {
#pragma omp critical(semsegmap_fpfh_error)
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
  return out;
}

}  // namespace semsegmap
