#include "semsegmap/segment/incremental_segmenter.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace semsegmap {

namespace {
constexpr SegmentId kUnassigned = -1;
constexpr SegmentId kGrowing = -2;  // queued in the region being grown this step
}  // namespace

IncrementalSegmenter::IncrementalSegmenter(const SegmentationConfig& config)
    : config_(config), distance_(config) {
  if (config.min_segment_points > config.max_segment_points)
    throw std::invalid_argument("segmentation.min_segment_points exceeds max_segment_points");
}

uint64_t IncrementalSegmenter::cellOf(const Eigen::Vector3f& p) const {
  const float inv = static_cast<float>(1.0 / config_.d_segment_m);
  const Eigen::Vector3i c(static_cast<int>(std::floor(p.x() * inv)),
                          static_cast<int>(std::floor(p.y() * inv)),
                          static_cast<int>(std::floor(p.z() * inv)));
  return packVoxelKey(c);
}

void IncrementalSegmenter::eraseFromCell(VoxelKey key, const Eigen::Vector3f& position) {
  auto it = cells_.find(cellOf(position));
  if (it == cells_.end()) return;
  auto& v = it->second;
  for (size_t k = 0; k < v.size(); ++k)
    if (v[k].key == key) {
      v[k] = v.back();
      v.pop_back();
      break;
    }
  if (v.empty()) cells_.erase(it);
}

SegmentationUpdate IncrementalSegmenter::update(const LocalMap& map, const LocalMapUpdate& mu,
                                                size_t frame_index, double timestamp_s) {
  SegmentationUpdate out;
  removeVoxels(mu.removed, out);
  // Grow a region from each newly active voxel that is not yet part of one.
  std::vector<SegmentId> changed, touched;
  std::vector<VoxelKey> region;
  for (VoxelKey seed : addVoxels(map, mu.newly_active)) {
    if (voxels_.at(seed).segment != kUnassigned) continue;
    growRegion(seed, region, touched);
    const SegmentId target = regionSegment(touched, frame_index, out, changed);
    SegmentState& st = segments_.at(target);
    for (VoxelKey k : region) {
      voxels_.at(k).segment = target;
      st.voxels.push_back(k);
    }
    st.live += region.size();
    if (std::find(changed.begin(), changed.end(), target) == changed.end())
      changed.push_back(target);
  }
  observeChanged(changed, map, frame_index, timestamp_s, out);
  return out;
}

// Voxels that left the local map leave their segments; a segment with none left is finished.
void IncrementalSegmenter::removeVoxels(const std::vector<VoxelKey>& removed,
                                        SegmentationUpdate& out) {
  for (VoxelKey key : removed) {
    auto it = voxels_.find(key);
    if (it == voxels_.end()) continue;
    const SegmentId id = it->second.segment;
    eraseFromCell(key, it->second.attributes.position);
    voxels_.erase(it);
    auto sit = segments_.find(id);
    if (sit == segments_.end()) continue;
    if (--sit->second.live == 0) {
      Segment done = finish(sit->second);
      segments_.erase(sit);
      if (!done.observations.empty()) out.finished.push_back(std::move(done));
    }
  }
}

// Registers the newly active voxels, with the attributes the distance needs; returns them.
std::vector<VoxelKey> IncrementalSegmenter::addVoxels(const LocalMap& map,
                                                      const std::vector<VoxelKey>& active) {
  std::vector<VoxelKey> seeds;
  seeds.reserve(active.size());
  for (VoxelKey key : active) {
    const Voxel* v = map.find(key);
    if (!v || !v->active || voxels_.count(key)) continue;
    VoxelEntry e;
    e.attributes.position = v->centroid;
    e.attributes.hue = v->hue();
    e.attributes.has_color = v->n_colored > 0;
    e.attributes.has_class = v->hasClass();
    e.attributes.class_id = v->semanticClass();
    VoxelEntry* entry = &voxels_.emplace(key, e).first->second;
    cells_[cellOf(e.attributes.position)].push_back({key, e.attributes, entry});
    seeds.push_back(key);
  }
  return seeds;
}

void IncrementalSegmenter::growRegion(VoxelKey seed, std::vector<VoxelKey>& region,
                                      std::vector<SegmentId>& touched) {
  region.clear();
  touched.clear();
  std::vector<VoxelKey> queue(1, seed);
  voxels_.at(seed).segment = kGrowing;
  const float inv = static_cast<float>(1.0 / config_.d_segment_m);
  while (!queue.empty()) {
    const VoxelKey u = queue.back();
    queue.pop_back();
    region.push_back(u);
    const DistanceVoxel a = voxels_.at(u).attributes;
    const Eigen::Vector3i c(static_cast<int>(std::floor(a.position.x() * inv)),
                            static_cast<int>(std::floor(a.position.y() * inv)),
                            static_cast<int>(std::floor(a.position.z() * inv)));
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          auto cell = cells_.find(packVoxelKey(c + Eigen::Vector3i(dx, dy, dz)));
          if (cell == cells_.end()) continue;
          for (const CellEntry& n : cell->second) {
            VoxelEntry& e = *n.entry;
            // Already in this region (or queued): nothing to learn from the distance.
            if (e.segment == kGrowing || !distance_.connected(a, n.attributes)) continue;
            if (e.segment >= 0) {
              if (std::find(touched.begin(), touched.end(), e.segment) == touched.end())
                touched.push_back(e.segment);
            } else if (e.segment == kUnassigned) {
              e.segment = kGrowing;
              queue.push_back(n.key);
            }
          }
        }
  }
}

SegmentId IncrementalSegmenter::regionSegment(const std::vector<SegmentId>& touched,
                                              size_t frame_index, SegmentationUpdate& out,
                                              std::vector<SegmentId>& changed) {
  if (touched.empty()) {
    const SegmentId id = next_id_++;
    SegmentState& st = segments_[id];
    st.segment.id = id;
    st.segment.first_frame = frame_index;
    return id;
  }
  // The oldest segment survives the merge, as in SegMap.
  const SegmentId target = *std::min_element(touched.begin(), touched.end());
  for (SegmentId other : touched)
    if (other != target) {
      absorb(target, other);
      out.merges.push_back({other, target});
      changed.erase(std::remove(changed.begin(), changed.end(), other), changed.end());
    }
  return target;
}

void IncrementalSegmenter::observeChanged(const std::vector<SegmentId>& changed,
                                          const LocalMap& map, size_t frame_index,
                                          double timestamp_s, SegmentationUpdate& out) {
  for (SegmentId id : changed) {
    SegmentState& st = segments_.at(id);
    st.segment.last_frame = frame_index;
    if (st.dropped || st.live > config_.max_segment_points) {
      // Too large to be a useful landmark (ground remnants, long walls): dropped for good, and
      // whatever grows into it later is dropped with it (absorb() passes it on). Reported once,
      // when it loses its observations.
      if (!st.segment.observations.empty()) out.dropped.push_back(id);
      st.dropped = true;
      st.segment.observations.clear();
      continue;
    }
    const double grown = static_cast<double>(st.last_observed) * (1.0 + config_.observation_growth);
    if (st.live >= config_.min_segment_points && (st.last_observed == 0 || st.live >= grown)) {
      observe(st, map, frame_index, timestamp_s);
      out.observed.push_back(id);
    }
  }
}

SegmentId IncrementalSegmenter::absorb(SegmentId survivor, SegmentId absorbed) {
  SegmentState& to = segments_.at(survivor);
  SegmentState& from = segments_.at(absorbed);
  for (VoxelKey k : from.voxels) {
    auto it = voxels_.find(k);
    if (it == voxels_.end() || it->second.segment != absorbed) continue;
    it->second.segment = survivor;
    to.voxels.push_back(k);
  }
  to.live += from.live;
  to.dropped = to.dropped || from.dropped;
  to.segment.first_frame = std::min(to.segment.first_frame, from.segment.first_frame);
  to.last_observed = std::max(to.last_observed, from.last_observed);
  segments_.erase(absorbed);
  return survivor;
}

void IncrementalSegmenter::observe(SegmentState& st, const LocalMap& map, size_t frame_index,
                                   double timestamp_s) {
  // Drop voxels that left (or moved to another segment) so the list stays proportional to `live`.
  const SegmentId id = st.segment.id;
  st.voxels.erase(std::remove_if(st.voxels.begin(), st.voxels.end(),
                                 [&](VoxelKey k) {
                                   auto it = voxels_.find(k);
                                   return it == voxels_.end() || it->second.segment != id;
                                 }),
                  st.voxels.end());
  SegmentObservation obs;
  obs.frame_index = frame_index;
  obs.timestamp_s = timestamp_s;
  obs.points.reserve(st.voxels.size());
  Votes<ClassId, 4> classes;
  Votes<uint16_t, 4> instances;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (VoxelKey k : st.voxels) {
    const Voxel* v = map.find(k);
    if (!v) continue;
    EnrichedPoint p;
    p.x = v->centroid.x();
    p.y = v->centroid.y();
    p.z = v->centroid.z();
    p.has_color = v->n_colored > 0;
    p.h = v->hue();
    p.s = v->saturation;
    p.v = v->value;
    p.has_class = v->hasClass();
    p.class_id = v->semanticClass();
    p.instance_id = v->instances.majority().first;
    if (p.has_class) classes.add(p.class_id);
    if (p.instance_id) instances.add(p.instance_id);
    sum += v->centroid.cast<double>();
    obs.points.push_back(p);
  }
  obs.n_points = obs.points.size();
  if (obs.n_points == 0) return;
  obs.centroid = sum / static_cast<double>(obs.n_points);
  obs.majority_class = classes.majority().first;
  const auto inst = instances.majority();
  obs.gt_instance = inst.first;
  obs.gt_purity = static_cast<float>(inst.second) / static_cast<float>(obs.n_points);
  if (!config_.keep_all_observation_points && !st.segment.observations.empty())
    st.segment.observations.back().points.clear();
  st.segment.observations.push_back(std::move(obs));
  st.last_observed = st.live;
}

Segment IncrementalSegmenter::finish(SegmentState& st) {
  if (st.dropped) return Segment{st.segment.id, {}, st.segment.first_frame, st.segment.last_frame};
  return std::move(st.segment);
}

std::vector<Segment> IncrementalSegmenter::finishAll() {
  std::vector<Segment> out;
  std::vector<SegmentId> ids;
  for (const auto& [id, st] : segments_) ids.push_back(id);
  std::sort(ids.begin(), ids.end());
  for (SegmentId id : ids) {
    Segment s = finish(segments_.at(id));
    if (!s.observations.empty()) out.push_back(std::move(s));
  }
  segments_.clear();
  voxels_.clear();
  cells_.clear();
  return out;
}

std::vector<const Segment*> IncrementalSegmenter::activeSegments() const {
  std::vector<const Segment*> out;
  for (const auto& [id, st] : segments_)
    if (!st.dropped && !st.segment.observations.empty()) out.push_back(&st.segment);
  std::sort(out.begin(), out.end(),
            [](const Segment* a, const Segment* b) { return a->id < b->id; });
  return out;
}

const Segment* IncrementalSegmenter::segment(SegmentId id) const {
  auto it = segments_.find(id);
  return it == segments_.end() ? nullptr : &it->second.segment;
}

SegmentId IncrementalSegmenter::segmentOf(VoxelKey key) const {
  auto it = voxels_.find(key);
  return it == voxels_.end() ? -1 : it->second.segment;
}

}  // namespace semsegmap
