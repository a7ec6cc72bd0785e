// The target map (paper section III-D): what a robot localizes against. Per segment only what
// localization needs: the descriptor of its final (most complete) observation, its centroid in
// the map frame, its majority class and size. Points are optional and for pictures only.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/class_table.h"
#include "semsegmap/core/pose.h"
#include "semsegmap/localize/scan_context.h"

namespace semsegmap {

struct MapSegment {
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();  // map frame
  uint32_t n_points = 0;
  ClassId majority_class = cls::kUnknown;
  std::vector<Eigen::Vector3f> points;  // optional: a subsample, map frame
  // A map merged from several sessions (pipeline/session_merge.h) keeps each session's
  // observation of a place both saw, under one segment id; a map of one run gives every entry
  // its own (its index).
  uint32_t segment = 0;
  uint16_t session = 0;   // index into TargetMap::sessions
  uint32_t keyframe = 0;  // the session's frame whose pose placed it (MapSession::trajectory)
};

// One drive that built part of a map: the first defines the map's frame, each later one was
// aligned to it by localizing against it (pipeline/session_merge.h).
struct MapSession {
  std::string name;              // the data it came from
  int64_t merged_unix_s = 0;     // when it joined the map
  std::vector<Pose> trajectory;  // its frames' poses in the map frame (empty for the first)
};

// The settings a map's segments depend on (voxel size, growing radius, penalties...), as
// "section.key" -> value text in the configuration's own words: a map records them (map format
// 2) because segments grown with other settings are other segments, whose descriptors do not
// match even with the same model. Kept in a fixed order; values are exact (formatted to
// round-trip), so equal text means equal settings.
using MapParameters = std::vector<std::pair<std::string, std::string>>;

struct TargetMap {
  std::string descriptor;   // descriptorName(): "semsegmap-net", "segmap-cnn", "eigen", "fpfh"
  std::string fingerprint;  // Describer::fingerprint(): the exact model the descriptors came from
  std::vector<MapSegment> segments;
  Eigen::MatrixXf descriptors;  // one row per segment
  MapParameters parameters;     // what it was built with; empty for a map made by hand
  // Scan contexts of the mapping run's scans (target_map.scan_context_apart_m), in the map frame:
  // a relocalization checks the places they propose beside those its segments vote for.
  ScanContextDatabase scan_contexts;
  // The sessions the map was merged from; empty for the map of one run (all its segments are
  // session 0's).
  std::vector<MapSession> sessions;
  std::string source;  // the file it was loaded from, for messages; empty for a map in memory

  size_t size() const { return segments.size(); }
  int dimension() const { return static_cast<int>(descriptors.cols()); }
};

struct TargetMapBuilderConfig {
  // A segment whose centroid lies within this distance of a segment added earlier replaces it:
  // the same object segmented again on a revisit (SegMap kept only the newest of such
  // duplicates), and the newer one saw at least as much of the place. 0 disables the filter.
  double duplicate_distance_m = 0.5;
  size_t max_points_per_segment = 0;  // points kept per segment for pictures (0: none)
  // Besides a segment's final observation, a mapping run keeps each earlier one whose centroid
  // lies at least this far from every other it keeps of that segment (0: the final one alone).
  // A segment seen from several places is the sum of those views, and a robot that comes back
  // with fewer of them (sparse scans, a wake-up) sees it as one of the earlier observations did:
  // its centroid and descriptor match those, not the final one's (README, KITTI 1576).
  double earlier_observations_apart_m = 0.0;
  // A map that stores segment points (max_points_per_segment > 0, which relocalization needs)
  // also stores the scan context of a mapped scan every this many metres of driving (0: none):
  // one scan's segments are partial and few, its scan context is whole, and on a sparse rig (a
  // VLP-32) it finds places the segments do not vote for (relocalizer.h). Off by default: at
  // about 2.4 kB each, every metre, they would outweigh the segments of a map many times over.
  double scan_context_apart_m = 0.0;
};

// Collects finished segments of a mapping run into a target map.
class TargetMapBuilder {
 public:
  TargetMapBuilder(std::string descriptor, std::string fingerprint, int dimension,
                   const TargetMapBuilderConfig& config = {});
  // `descriptor` has `dimension` entries; `points` may be empty.
  void add(const MapSegment& segment, const Eigen::VectorXf& descriptor);
  // The settings the segments were made with (pipeline/map_parameters.h), copied into the map.
  void setParameters(MapParameters parameters) { parameters_ = std::move(parameters); }
  // A mapped scan's scan context, made in the frame T_map_scan (levelled: z up).
  void addScan(ScanContext context, const Pose& T_map_scan) {
    scans_.add(std::move(context), T_map_scan);
  }
  size_t duplicatesRemoved() const { return duplicates_; }
  TargetMap build() const;

 private:
  std::string descriptor_, fingerprint_;
  int dimension_;
  TargetMapBuilderConfig config_;
  MapParameters parameters_;
  ScanContextDatabase scans_;
  std::vector<MapSegment> segments_;
  std::vector<Eigen::VectorXf> descriptors_;
  std::vector<bool> alive_;
  size_t duplicates_ = 0;
};

// At most `max_points` evenly spaced points of `points` (the optional picture points).
std::vector<Eigen::Vector3f> subsamplePoints(const std::vector<Eigen::Vector3f>& points,
                                             size_t max_points);

// Throws std::runtime_error "<map_name>: ..." (the map's file, say) when the map's descriptors
// cannot be compared with those of the running describer (another kind, dimension or model).
void checkMapCompatible(const std::string& map_name, const TargetMap& map,
                        const std::string& descriptor, const std::string& fingerprint,
                        int dimension);

// A recorded setting that the running configuration has otherwise; a key only one of them has
// differs too (the missing side's value is "(none)"), so a map of an older build that did not
// record a key is not taken for a match.
struct MapParameterDifference {
  std::string key, map_value, config_value;
};
std::vector<MapParameterDifference> mapParameterDifferences(const MapParameters& map,
                                                            const MapParameters& config);
// "<map_name>: <key>: the map was built with <map value>, the configuration has <config value>"
std::string describeDifference(const std::string& map_name, const MapParameterDifference& d);

}  // namespace semsegmap
