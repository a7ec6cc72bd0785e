// Incremental region growing (paper section III-B, after SegMap): each update grows segments
// only from the voxels that became active, linking voxels whose semantic distance is within
// d_segment. When growth touches existing segments they merge and the oldest id survives.
// Segments whose voxels all left the local map are handed out as finished, so memory stays
// bounded however long the robot drives.
#pragma once

#include <unordered_map>
#include <vector>

#include "semsegmap/local_map/local_map.h"
#include "semsegmap/segment/segment.h"
#include "semsegmap/segment/semantic_distance.h"

namespace semsegmap {

struct SegmentMerge {
  SegmentId absorbed;
  SegmentId survivor;
};

struct SegmentationUpdate {
  std::vector<SegmentId> observed;  // segments that got a new observation this step
  std::vector<SegmentMerge> merges;
  std::vector<Segment> finished;  // left the local map; their last observation is final
  // Reported before, now too large to be a landmark: never finished, so whoever kept them
  // (the local segments' descriptors) lets them go here.
  std::vector<SegmentId> dropped;
};

class IncrementalSegmenter {
 public:
  explicit IncrementalSegmenter(const SegmentationConfig& config);

  SegmentationUpdate update(const LocalMap& map, const LocalMapUpdate& map_update,
                            size_t frame_index, double timestamp_s);
  // Everything still in the local map, as finished segments (end of a run).
  std::vector<Segment> finishAll();

  // Segments currently in the local map that are reported (not too small, not dropped).
  std::vector<const Segment*> activeSegments() const;
  const Segment* segment(SegmentId id) const;
  // Segment of an active voxel, or -1.
  SegmentId segmentOf(VoxelKey key) const;
  const SegmentationConfig& config() const { return config_; }

 private:
  struct VoxelEntry {
    DistanceVoxel attributes;
    SegmentId segment = -1;
  };
  struct SegmentState {
    Segment segment;
    std::vector<VoxelKey> voxels;  // may hold voxels that left; `live` counts those that did not
    size_t live = 0;
    size_t last_observed = 0;
    bool dropped = false;
  };

  struct CellEntry {
    VoxelKey key;
    DistanceVoxel attributes;
    // The voxel's entry in voxels_ (unordered_map nodes never move), so that region growing
    // reads a neighbour's segment without a hash lookup; erased before the entry is.
    VoxelEntry* entry;
  };

  uint64_t cellOf(const Eigen::Vector3f& p) const;
  void eraseFromCell(VoxelKey key, const Eigen::Vector3f& position);
  SegmentId absorb(SegmentId survivor, SegmentId absorbed);
  // The steps of update().
  void removeVoxels(const std::vector<VoxelKey>& removed, SegmentationUpdate& out);
  std::vector<VoxelKey> addVoxels(const LocalMap& map, const std::vector<VoxelKey>& active);
  // The connected unassigned voxels around `seed` into `region`, and the segments they touch.
  void growRegion(VoxelKey seed, std::vector<VoxelKey>& region, std::vector<SegmentId>& touched);
  // A new segment, or the oldest touched one after absorbing the others.
  SegmentId regionSegment(const std::vector<SegmentId>& touched, size_t frame_index,
                          SegmentationUpdate& out, std::vector<SegmentId>& changed);
  void observeChanged(const std::vector<SegmentId>& changed, const LocalMap& map,
                      size_t frame_index, double timestamp_s, SegmentationUpdate& out);
  void observe(SegmentState& s, const LocalMap& map, size_t frame_index, double timestamp_s);
  Segment finish(SegmentState& s);

  SegmentationConfig config_;
  SemanticDistance distance_;
  SegmentId next_id_ = 0;
  std::unordered_map<VoxelKey, VoxelEntry> voxels_;
  // Active voxels in a coarse grid of d_segment cells: every voxel within d_segment of a point
  // is in the 27 cells around it, and the distance needs no lookup of the voxel itself.
  std::unordered_map<uint64_t, std::vector<CellEntry>> cells_;
  std::unordered_map<SegmentId, SegmentState> segments_;
};

}  // namespace semsegmap
