#include "semsegmap/odometry/voxel_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

namespace semsegmap {

namespace {

constexpr uint64_t kEmpty = UINT64_MAX;  // no packed key has all 64 bits set (bit 63 is unused)
constexpr int kBits = 21;
constexpr int64_t kOffset = int64_t{1} << (kBits - 1);
constexpr uint64_t kFieldMask = (uint64_t{1} << kBits) - 1;

uint64_t packKey(int64_t x, int64_t y, int64_t z) {
  // Indices outside +-2^20 voxels wrap; at a 0.05 m voxel that is 52 km from the origin.
  return (static_cast<uint64_t>(x + kOffset) & kFieldMask) |
         ((static_cast<uint64_t>(y + kOffset) & kFieldMask) << kBits) |
         ((static_cast<uint64_t>(z + kOffset) & kFieldMask) << (2 * kBits));
}

uint64_t mixKey(uint64_t k) {
  // The finaliser of MurmurHash3: neighbouring voxels land in unrelated slots.
  k ^= k >> 33;
  k *= 0xff51afd7ed558ccdULL;
  k ^= k >> 33;
  return k;
}

// Voxels whose planes are this flat (smallest spread over the middle one) count as planar.
constexpr double kPlanarity = 0.1;
constexpr double kMinPlanePoints = 5;
// The second-largest spread of a plane, as a fraction of the voxel size.
constexpr double kMinSpread = 0.15;

}  // namespace

uint64_t voxelKeyOf(const Eigen::Vector3d& p, double inverse_voxel_size) {
  return packKey(static_cast<int64_t>(std::floor(p.x() * inverse_voxel_size)),
                 static_cast<int64_t>(std::floor(p.y() * inverse_voxel_size)),
                 static_cast<int64_t>(std::floor(p.z() * inverse_voxel_size)));
}

void VoxelIndex::clear(size_t expected) {
  size_t capacity = 16;
  while (capacity < 2 * expected) capacity *= 2;  // at most half full: short probe sequences
  keys_.assign(capacity, kEmpty);
  values_.assign(capacity, kNone);
  mask_ = capacity - 1;
  size_ = 0;
}

uint32_t VoxelIndex::find(uint64_t key) const {
  if (keys_.empty()) return kNone;
  for (uint64_t slot = mixKey(key) & mask_;; slot = (slot + 1) & mask_) {
    if (keys_[slot] == key) return values_[slot];
    if (keys_[slot] == kEmpty) return kNone;
  }
}

uint32_t VoxelIndex::findOrInsert(uint64_t key, uint32_t value) {
  if (2 * (size_ + 1) > keys_.size()) grow();
  for (uint64_t slot = mixKey(key) & mask_;; slot = (slot + 1) & mask_) {
    if (keys_[slot] == key) return values_[slot];
    if (keys_[slot] != kEmpty) continue;
    keys_[slot] = key;
    values_[slot] = value;
    ++size_;
    return value;
  }
}

void VoxelIndex::grow() {
  const std::vector<uint64_t> keys = std::move(keys_);
  const std::vector<uint32_t> values = std::move(values_);
  clear(std::max<size_t>(size_ + 1, keys.size()));
  for (size_t i = 0; i < keys.size(); ++i)
    if (keys[i] != kEmpty) findOrInsert(keys[i], values[i]);
}

std::vector<Eigen::Vector3d> voxelDownsample(const std::vector<Eigen::Vector3d>& points,
                                             double voxel_size_m) {
  VoxelIndex seen;
  seen.clear(points.size() / 4);
  std::vector<Eigen::Vector3d> kept;
  const double inverse = 1.0 / voxel_size_m;
  for (const Eigen::Vector3d& p : points) {
    const uint32_t next = static_cast<uint32_t>(kept.size());
    if (seen.findOrInsert(voxelKeyOf(p, inverse), next) == next) kept.push_back(p);
  }
  return kept;
}

VoxelMap::VoxelMap(double voxel_size_m, int max_points_per_voxel)
    : voxel_size_(voxel_size_m),
      inverse_voxel_size_(1.0 / voxel_size_m),
      max_points_(static_cast<size_t>(std::max(1, max_points_per_voxel))) {
  index_.clear(0);
}

VoxelMap::Voxel& VoxelMap::voxelAt(const Eigen::Vector3d& p) {
  const uint64_t key = voxelKeyOf(p, inverse_voxel_size_);
  const uint32_t next = static_cast<uint32_t>(voxels_.size());
  const uint32_t at = index_.findOrInsert(key, next);
  if (at == next) {
    voxels_.emplace_back();
    voxels_.back().key = key;
    voxels_.back().corner = (p * inverse_voxel_size_).array().floor() * voxel_size_;
    voxels_.back().points.reserve(max_points_);
  }
  return voxels_[at];
}

void VoxelMap::add(const std::vector<Eigen::Vector3d>& points,
                   const std::vector<Eigen::Vector3d>& plane_points) {
  for (const Eigen::Vector3d& p : points) {
    Voxel& v = voxelAt(p);
    if (v.points.size() < max_points_) v.points.push_back(p.cast<float>());
  }
  for (const Eigen::Vector3d& p : plane_points) {
    Voxel& v = voxelAt(p);
    const Eigen::Vector3d d = p - v.corner;
    v.count += 1.0;
    v.sum += d;
    v.sum_sq.noalias() += d * d.transpose();
    v.dirty = true;
  }
  for (Voxel& v : voxels_)
    if (v.dirty) fitNormal(v);
}

void VoxelMap::fitNormal(Voxel& voxel) const {
  voxel.dirty = false;
  voxel.normal.setZero();
  voxel.linear = false;
  if (voxel.count < kMinPlanePoints) return;
  const Eigen::Vector3d mean = voxel.sum / voxel.count;
  const Eigen::Matrix3d cov = voxel.sum_sq / voxel.count - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
  eig.computeDirect(cov);  // eigenvalues in increasing order
  const Eigen::Vector3d spread = eig.eigenvalues().cwiseMax(0.0);
  // Points along one line (a single LiDAR ring crossing the voxel) fix no plane: the normal
  // would be any direction across the line, and rings move with the sensor, so matching them
  // pulls the motion towards zero. Such voxels give no correspondence at all.
  voxel.linear = spread(1) < kMinSpread * kMinSpread * voxel_size_ * voxel_size_;
  if (!voxel.linear && spread(0) <= kPlanarity * spread(1))
    voxel.normal = eig.eigenvectors().col(0).normalized().cast<float>();
}

void VoxelMap::removeFarFrom(const Eigen::Vector3d& center, double max_distance_m) {
  const float limit_sq = static_cast<float>(max_distance_m * max_distance_m);
  const Eigen::Vector3f c = center.cast<float>();
  const size_t before = voxels_.size();
  voxels_.erase(std::remove_if(voxels_.begin(), voxels_.end(),
                               [&](const Voxel& v) {
                                 return (v.corner.cast<float>() - c).squaredNorm() > limit_sq;
                               }),
                voxels_.end());
  if (voxels_.size() != before) rebuildIndex();
}

void VoxelMap::rebuildIndex() {
  index_.clear(voxels_.size());
  for (size_t i = 0; i < voxels_.size(); ++i)
    index_.findOrInsert(voxels_[i].key, static_cast<uint32_t>(i));
}

namespace {

// The 27 neighbour offsets, the query's own voxel first, then those sharing a face, an edge, a
// corner: the nearer ones first, so that the best distance found prunes the farther ones.
std::vector<Eigen::Vector3i> neighbourOffsets() {
  std::vector<Eigen::Vector3i> offsets;
  for (int shared = 0; shared <= 3; ++shared)
    for (int x = -1; x <= 1; ++x)
      for (int y = -1; y <= 1; ++y)
        for (int z = -1; z <= 1; ++z)
          if ((x != 0) + (y != 0) + (z != 0) == shared) offsets.emplace_back(x, y, z);
  return offsets;
}

}  // namespace

MapNeighbour VoxelMap::closest(const Eigen::Vector3d& query, double max_distance_m,
                               bool near_only) const {
  static const std::vector<Eigen::Vector3i> kOffsets = neighbourOffsets();
  const Eigen::Vector3d scaled = query * inverse_voxel_size_;
  const Eigen::Vector3d cell = scaled.array().floor();
  // Distance from the query to the lower and upper faces of its voxel, per axis.
  const Eigen::Vector3d below = (scaled - cell) * voxel_size_;
  const Eigen::Vector3d above = Eigen::Vector3d::Constant(voxel_size_) - below;
  const int64_t cx = static_cast<int64_t>(cell.x()), cy = static_cast<int64_t>(cell.y()),
                cz = static_cast<int64_t>(cell.z());
  const Eigen::Vector3f q = query.cast<float>();
  float best_sq = static_cast<float>(max_distance_m * max_distance_m);
  const Voxel* best_voxel = nullptr;
  const Eigen::Vector3f* best_point = nullptr;
  for (const Eigen::Vector3i& o : kOffsets) {
    // A voxel whose nearest face is farther than the best match so far cannot hold a better one.
    double box_sq = 0.0;
    for (int a = 0; a < 3; ++a)
      if (o(a) != 0) {
        const double d = o(a) < 0 ? below(a) : above(a);
        if (near_only && d > 0.5 * voxel_size_) box_sq = 1e300;
        box_sq += d * d;
      }
    if (box_sq >= best_sq) continue;
    const uint32_t at = index_.find(packKey(cx + o.x(), cy + o.y(), cz + o.z()));
    if (at == VoxelIndex::kNone) continue;
    for (const Eigen::Vector3f& p : voxels_[at].points) {
      const float d = (p - q).squaredNorm();
      if (d >= best_sq) continue;
      best_sq = d;
      best_point = &p;
      best_voxel = &voxels_[at];
    }
  }
  MapNeighbour best;
  if (!best_voxel) return best;
  best.found = true;
  best.point = best_point->cast<double>();
  best.normal = best_voxel->normal.cast<double>();
  best.linear = best_voxel->linear;
  best.distance_sq = best_sq;
  return best;
}

size_t VoxelMap::pointCount() const {
  size_t n = 0;
  for (const Voxel& v : voxels_) n += v.points.size();
  return n;
}

std::vector<Eigen::Vector3d> VoxelMap::points() const {
  std::vector<Eigen::Vector3d> out;
  out.reserve(pointCount());
  for (const Voxel& v : voxels_)
    for (const Eigen::Vector3f& p : v.points) out.push_back(p.cast<double>());
  return out;
}

}  // namespace semsegmap
