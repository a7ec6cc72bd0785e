#include "semsegmap/local_map/local_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace semsegmap {

namespace {
constexpr int kKeyBits = 21;
constexpr int64_t kKeyOffset = int64_t{1} << (kKeyBits - 1);
constexpr uint64_t kKeyMask = (uint64_t{1} << kKeyBits) - 1;
}  // namespace

VoxelKey packVoxelKey(const Eigen::Vector3i& i) {
  return (static_cast<uint64_t>(i.x() + kKeyOffset) & kKeyMask) |
         ((static_cast<uint64_t>(i.y() + kKeyOffset) & kKeyMask) << kKeyBits) |
         ((static_cast<uint64_t>(i.z() + kKeyOffset) & kKeyMask) << (2 * kKeyBits));
}

Eigen::Vector3i unpackVoxelKey(VoxelKey key) {
  return {static_cast<int>(static_cast<int64_t>(key & kKeyMask) - kKeyOffset),
          static_cast<int>(static_cast<int64_t>((key >> kKeyBits) & kKeyMask) - kKeyOffset),
          static_cast<int>(static_cast<int64_t>((key >> (2 * kKeyBits)) & kKeyMask) - kKeyOffset)};
}

float Voxel::hue() const {
  if (n_colored == 0) return 0.0f;
  float h = std::atan2(hue_sin, hue_cos) / (2.0f * static_cast<float>(M_PI));
  if (h < 0) h += 1.0f;
  return h >= 1.0f ? 0.0f : h;
}

LocalMap::LocalMap(const LocalMapConfig& config, const ClassTable& classes) : config_(config) {
  if (!(config.voxel_size_m > 0))
    throw std::invalid_argument("local_map.voxel_size_m must be positive");
  if (!(config.radius_m > 0)) throw std::invalid_argument("local_map.radius_m must be positive");
  if (config.min_points_per_voxel < 1)
    throw std::invalid_argument("local_map.min_points_per_voxel must be at least 1");
  if (!(config.dynamic_vote_share >= 0 && config.dynamic_vote_share < 1))
    throw std::invalid_argument("local_map.dynamic_vote_share must be in [0, 1)");
  const bool by_point = config.dynamic_removal == DynamicRemoval::kPoint;
  drop_class_.assign(1 << 16, 0);
  dynamic_class_.assign(1 << 16, 0);
  for (const auto& c : classes.classes()) {
    const bool dynamic = config.remove_dynamic_classes && c.dynamic;
    drop_class_[c.id] = (dynamic && by_point) || (config.remove_ground_classes && c.ground);
    dynamic_class_[c.id] = dynamic && !by_point;
  }
}

DynamicRemoval parseDynamicRemoval(const std::string& name) {
  if (name == "point") return DynamicRemoval::kPoint;
  if (name == "voxel") return DynamicRemoval::kVoxel;
  throw std::invalid_argument("expected point or voxel, got '" + name + "'");
}

std::string dynamicRemovalName(DynamicRemoval removal) {
  return removal == DynamicRemoval::kPoint ? "point" : "voxel";
}

Eigen::Vector3i LocalMap::voxelIndex(const Eigen::Vector3f& p) const {
  const float inv = static_cast<float>(1.0 / config_.voxel_size_m);
  return {static_cast<int>(std::floor(p.x() * inv)), static_cast<int>(std::floor(p.y() * inv)),
          static_cast<int>(std::floor(p.z() * inv))};
}

const Voxel* LocalMap::find(VoxelKey key) const {
  auto it = voxels_.find(key);
  return it == voxels_.end() ? nullptr : &it->second;
}

// A point with a class is filtered by it; an unobserved one by its geometry, or as unobserved
// when the scan has classes elsewhere and the config drops what no camera saw.
bool LocalMap::dropped(const EnrichedPoint& q, bool ground, bool drop_unobserved) const {
  if (ground && (config_.geometric_ground_removal || !q.has_class)) return true;
  if (!q.has_class) return drop_unobserved;
  return drop_class_[q.class_id] || (config_.remove_unknown_class && q.class_id == cls::kUnknown);
}

LocalMapUpdate LocalMap::update(const EnrichedCloud& scan, const Pose& T_map_lidar,
                                const Eigen::Vector2d& robot_xy) {
  LocalMapUpdate out;
  size_t classified = 0;
  for (const EnrichedPoint& q : scan) classified += q.has_class;
  out.points_unobserved = scan.size() - classified;
  const bool geometric = config_.geometric_ground_removal || out.points_unobserved > 0;
  // Only the points without a class are asked, unless the ground goes by geometry everywhere.
  if (geometric)
    ground_mask_ = markGround(scan, T_map_lidar, config_.ground, !config_.geometric_ground_removal);
  const bool drop_unobserved = config_.remove_unobserved && classified > 0;
  const Eigen::Matrix3f R = T_map_lidar.linear().cast<float>();
  const Eigen::Vector3f t = T_map_lidar.translation().cast<float>();
  const Eigen::Vector2f center = robot_xy.cast<float>();
  const float r2 = static_cast<float>(config_.radius_m * config_.radius_m);
  ++scan_;
  std::vector<VoxelKey> pending;

  for (size_t k = 0; k < scan.size(); ++k) {
    const EnrichedPoint& q = scan[k];
    if (dropped(q, geometric && ground_mask_[k], drop_unobserved)) {
      ++out.points_filtered;
      continue;
    }
    const Eigen::Vector3f p = R * Eigen::Vector3f(q.x, q.y, q.z) + t;
    if ((p.head<2>() - center).squaredNorm() > r2) {
      ++out.points_filtered;
      continue;
    }
    const Eigen::Vector3i idx = voxelIndex(p);
    const VoxelKey key = packVoxelKey(idx);
    auto [it, created] = voxels_.try_emplace(key);
    if (created) tiles_[tileOf(idx)].push_back(key);
    Voxel& v = it->second;
    ++v.n_points;
    v.centroid += (p - v.centroid) / static_cast<float>(v.n_points);
    if (q.has_color) {
      ++v.n_colored;
      const float inv_n = 1.0f / static_cast<float>(v.n_colored);
      const float angle = 2.0f * static_cast<float>(M_PI) * q.h;
      v.hue_cos += (std::cos(angle) - v.hue_cos) * inv_n;
      v.hue_sin += (std::sin(angle) - v.hue_sin) * inv_n;
      v.saturation += (q.s - v.saturation) * inv_n;
      v.value += (q.v - v.value) * inv_n;
    }
    if (q.has_class) {
      ++v.n_classified;
      if (dynamic_class_[q.class_id])
        ++v.n_dynamic;
      else
        v.classes.add(q.class_id);
    }
    if (q.instance_id != 0) v.instances.add(q.instance_id);
    ++out.points_inserted;
    // Considered for activation once the scan is in, when its votes are counted; in the order
    // voxels reach the minimum, so that without dynamic votes the order is that of the points.
    if (!v.active && v.pending_scan != scan_ && v.n_points >= config_.min_points_per_voxel) {
      v.pending_scan = scan_;
      pending.push_back(key);
    }
  }
  for (VoxelKey key : pending) {
    Voxel& v = voxels_.at(key);
    // The share among the points that have a class: unobserved points say nothing either way.
    if (v.n_dynamic > config_.dynamic_vote_share * v.n_classified) continue;
    v.active = true;
    ++active_count_;
    out.newly_active.push_back(key);
  }

  // The cylinder follows the robot: whatever is now outside it is forgotten.
  dropOutside(center, out);
  return out;
}

uint64_t LocalMap::tileOf(const Eigen::Vector3i& i) const {
  const auto floorDiv = [this](int a) {
    return a >= 0 ? a / tile_voxels_ : -((-a + tile_voxels_ - 1) / tile_voxels_);
  };
  return packVoxelKey(Eigen::Vector3i(floorDiv(i.x()), floorDiv(i.y()), 0));
}

void LocalMap::dropOutside(const Eigen::Vector2f& center, LocalMapUpdate& out) {
  const float voxel = static_cast<float>(config_.voxel_size_m);
  const float tile = voxel * static_cast<float>(tile_voxels_);
  const float r = static_cast<float>(config_.radius_m);
  auto drop = [&](VoxelKey key) {
    auto it = voxels_.find(key);
    if (it->second.active) {
      out.removed.push_back(key);
      --active_count_;
    }
    voxels_.erase(it);
  };
  for (auto t = tiles_.begin(); t != tiles_.end();) {
    const Eigen::Vector3i ti = unpackVoxelKey(t->first);
    const Eigen::Vector2f lo(ti.x() * tile, ti.y() * tile);
    const Eigen::Vector2f hi = lo + Eigen::Vector2f::Constant(tile);
    const Eigen::Vector2f nearest = center.cwiseMax(lo).cwiseMin(hi);
    const Eigen::Vector2f farthest((center.x() - lo.x() > hi.x() - center.x()) ? lo.x() : hi.x(),
                                   (center.y() - lo.y() > hi.y() - center.y()) ? lo.y() : hi.y());
    if ((farthest - center).norm() <= r) {  // wholly inside
      ++t;
      continue;
    }
    std::vector<VoxelKey>& keys = t->second;
    if ((nearest - center).norm() > r) {  // wholly outside
      for (VoxelKey k : keys) drop(k);
      t = tiles_.erase(t);
      continue;
    }
    // The rim crosses this tile: decide voxel by voxel (by voxel centre).
    keys.erase(std::remove_if(keys.begin(), keys.end(),
                              [&](VoxelKey k) {
                                const Eigen::Vector3i idx = unpackVoxelKey(k);
                                const Eigen::Vector2f c((idx.x() + 0.5f) * voxel,
                                                        (idx.y() + 0.5f) * voxel);
                                if ((c - center).norm() <= r) return false;
                                drop(k);
                                return true;
                              }),
               keys.end());
    if (keys.empty())
      t = tiles_.erase(t);
    else
      ++t;
  }
}

}  // namespace semsegmap
