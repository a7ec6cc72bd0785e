// Written from the 3DSmoothNet paper's description (section 3.1: local reference frame, SDV
// voxel grid); the sums run in double so that the frame does not depend on the order of the
// points beyond the last float bit.
#include "semsegmap/describe/smoothnet_input.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>

#include "semsegmap/describe/net_input.h"

namespace semsegmap {

namespace {

// Below this share of the largest spread a direction is none: points on a line or at one place.
constexpr double kDegenerate = 1e-6;

// x of the frame: the tangent direction that the points far from the tangent plane pull towards,
// or for a flat patch the direction of largest spread turned towards its longer side.
Eigen::Vector3d tangentAxis(const std::vector<Eigen::Vector3f>& support, const Eigen::Vector3d& p,
                            const Eigen::Vector3d& z, const Eigen::Vector3d& largest,
                            double radius) {
  Eigen::Vector3d pull = Eigen::Vector3d::Zero();
  double skew = 0.0;
  for (const Eigen::Vector3f& q : support) {
    const Eigen::Vector3d d = q.cast<double>() - p;
    const double alpha = std::pow(std::max(0.0, radius - d.norm()), 2);
    const double height = d.dot(z);
    pull += alpha * height * height * (d - height * z);
    skew += alpha * std::pow(d.dot(largest), 3);
  }
  // pull is in length^5 (alpha^2 height^2 offset): compared with the same power of the radius.
  if (pull.norm() > kDegenerate * std::pow(radius, 5) * static_cast<double>(support.size()))
    return pull.normalized();
  const Eigen::Vector3d x = largest - largest.dot(z) * z;
  return (skew < 0 ? -x : x).normalized();
}

}  // namespace

bool localReferenceFrame(const std::vector<Eigen::Vector3f>& support,
                         const Eigen::Vector3f& keypoint, float radius, Eigen::Matrix3f* axes) {
  if (support.size() < 3 || !(radius > 0)) return false;
  const Eigen::Vector3d p = keypoint.cast<double>();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3f& q : support) {
    const Eigen::Vector3d d = q.cast<double>() - p;
    covariance += d * d.transpose();
  }
  covariance /= static_cast<double>(support.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  const Eigen::Vector3d spread = eigen.eigenvalues();  // ascending
  if (!(spread[2] > 0) || spread[1] < kDegenerate * spread[2]) return false;
  Eigen::Vector3d z = eigen.eigenvectors().col(0);
  double side = 0.0;
  for (const Eigen::Vector3f& q : support) side += (q.cast<double>() - p).dot(z);
  if (side < 0) z = -z;
  const Eigen::Vector3d x = tangentAxis(support, p, z, eigen.eigenvectors().col(2), radius);
  const Eigen::Vector3d y = z.cross(x);
  axes->row(0) = x.cast<float>();
  axes->row(1) = y.cast<float>();
  axes->row(2) = z.cast<float>();
  return true;
}

std::vector<float> sdvGrid(const std::vector<Eigen::Vector3f>& support,
                           const Eigen::Vector3f& keypoint, const Eigen::Matrix3f& axes,
                           float radius, int voxels) {
  if (voxels < 1 || !(radius > 0))
    throw std::invalid_argument("sdvGrid: needs a positive radius and at least one voxel");
  const size_t w = static_cast<size_t>(voxels);
  const float side = 2.0f * radius / static_cast<float>(voxels);
  // Weights of sigma = half a cell, cut at 3 sigma: a point reaches the ~14 cells around it.
  const float h = 0.5f * side, reach = 3.0f * h;
  std::vector<double> sum(w * w * w, 0.0);
  std::vector<uint32_t> count(w * w * w, 0);
  for (const Eigen::Vector3f& q : support) {
    const Eigen::Vector3f local = axes * (q - keypoint);
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      // Cells whose centre -radius + (i + 0.5) side lies within `reach` of the point.
      lo[a] = std::max(0, static_cast<int>(std::ceil((local[a] - reach + radius) / side - 0.5f)));
      hi[a] = std::min(voxels - 1,
                       static_cast<int>(std::floor((local[a] + reach + radius) / side - 0.5f)));
    }
    for (int i = lo[0]; i <= hi[0]; ++i)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int k = lo[2]; k <= hi[2]; ++k) {
          const Eigen::Vector3f centre((i + 0.5f) * side - radius, (j + 0.5f) * side - radius,
                                       (k + 0.5f) * side - radius);
          const float d2 = (local - centre).squaredNorm();
          if (d2 > reach * reach) continue;
          const size_t cell =
              (static_cast<size_t>(i) * w + static_cast<size_t>(j)) * w + static_cast<size_t>(k);
          sum[cell] += std::exp(-d2 / (2.0f * h * h));
          ++count[cell];
        }
  }
  double total = 0.0;
  for (size_t c = 0; c < sum.size(); ++c)
    if (count[c] > 0) total += sum[c] /= count[c];
  std::vector<float> grid(sum.size(), 0.0f);
  if (total > 0)
    for (size_t c = 0; c < sum.size(); ++c) grid[c] = static_cast<float>(sum[c] / total);
  return grid;
}

std::vector<Eigen::Vector3f> pointsWithin(const std::vector<Eigen::Vector3f>& cloud,
                                          const Eigen::Vector3f& centre, float radius) {
  std::vector<Eigen::Vector3f> out;
  const float r2 = radius * radius;
  for (const Eigen::Vector3f& q : cloud)
    if ((q - centre).squaredNorm() <= r2) out.push_back(q);
  return out;
}

std::vector<float> keypointGrid(const std::vector<Eigen::Vector3f>& cloud,
                                const Eigen::Vector3f& keypoint, float radius, int voxels) {
  // The paper's spherical support: the frame and the grid see the same points (the grid's
  // corners stay empty).
  const std::vector<Eigen::Vector3f> support = pointsWithin(cloud, keypoint, radius);
  Eigen::Matrix3f axes;
  if (!localReferenceFrame(support, keypoint, radius, &axes))
    return std::vector<float>(static_cast<size_t>(voxels) * voxels * voxels, 0.0f);
  return sdvGrid(support, keypoint, axes, radius, voxels);
}

std::vector<float> smoothNetSample(const EnrichedCloud& segment, int keypoints, float radius,
                                   int voxels, uint64_t salt) {
  if (segment.empty()) throw std::invalid_argument("smoothNetSample: segment has no points");
  std::vector<Eigen::Vector3f> cloud;
  cloud.reserve(segment.size());
  for (const EnrichedPoint& p : segment) cloud.emplace_back(p.x, p.y, p.z);
  std::vector<float> out;
  out.reserve(static_cast<size_t>(keypoints) * voxels * voxels * voxels);
  for (const uint32_t i : hashSubsample(segment, keypoints, salt)) {
    const std::vector<float> grid = keypointGrid(cloud, cloud[i], radius, voxels);
    out.insert(out.end(), grid.begin(), grid.end());
  }
  return out;
}

}  // namespace semsegmap
