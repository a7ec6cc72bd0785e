// A new session (one drive) joining a map that earlier sessions built ([fleet], `semsegmap map
// --into`). The drive is mapped on its own odometry, in its own frame, and every frame its local
// segments are localized against the map. Each localization ties that frame to the map's frame;
// a pose graph of the drive's odometry edges and these ties (robust, as loop edges) gives every
// frame's pose in the map, and each of the session's segments follows the pose of the frame that
// placed it. Joined to the map, a segment that an older session saw too (same class, centroids
// within session_merge.same_segment_m) becomes an observation of that segment: both observations
// stay, under one segment id. A session with fewer than session_merge.min_localizations stays
// separate: its map is returned in its own frame, never merged at the map's origin.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "semsegmap/graph/pose_graph.h"
#include "semsegmap/localize/localizer.h"
#include "semsegmap/pipeline/modes.h"

namespace semsegmap {

// A frame of the session localized against the map.
struct SessionTie {
  size_t frame = 0;                    // index into the session's trajectory
  Pose T_map_base = Pose::Identity();  // as the localization put it
  int inliers = 0;
};

struct MergedSession {
  // Tied to the map by at least session_merge.min_localizations localizations.
  bool aligned = false;
  // Aligned: the map with the session joined, its last MapSession the new one. Not aligned: the
  // session's own map in its own frame, one session, never merged.
  TargetMap map;
  std::vector<SessionTie> ties;
  size_t entries = 0;                // the session's map entries
  size_t same_segments = 0;          // of them, observations of a segment the map held already
  double mean_tie_residual_m = 0.0;  // after the pose graph: localizations against the poses
  MappingRun mapping;                // the session's own mapping run (its frame, its stats)
};

class SessionMerge {
 public:
  // Throws std::runtime_error naming the map when its descriptors or settings are not the
  // configuration's (as localization does).
  SessionMerge(const PipelineConfig& config, const DatasetInfo& info,
               std::shared_ptr<const TargetMap> map, std::shared_ptr<Describer> describer,
               PoseSource poses = PoseSource::kOdometry, const FrontEndStages& stages = {});
  void process(const Frame& frame);
  // Once, after the last frame. `name` and `now_unix_s` describe the new session.
  MergedSession finish(const std::string& name, int64_t now_unix_s);
  const std::vector<SessionTie>& ties() const { return ties_; }

 private:
  PipelineConfig config_;
  std::shared_ptr<const TargetMap> map_;
  MappingSession mapping_;
  Localizer localizer_;
  std::vector<SessionTie> ties_;
  size_t frames_ = 0;
};

MergedSession runSessionMerge(FrameSource& source, const PipelineConfig& config,
                              std::shared_ptr<const TargetMap> map,
                              std::shared_ptr<Describer> describer, const std::string& name,
                              int64_t now_unix_s, PoseSource poses = PoseSource::kOdometry,
                              const RunOptions& options = {});

// The poses of a session's frames in the map frame from its own trajectory (`T_odom_base`, one
// per frame) and its ties: node 0 of the graph is the map's frame, held fixed; the first guess
// is the trajectory moved rigidly by the tie with the most inliers. Needs at least one tie.
std::vector<Pose> alignTrajectory(const std::vector<Pose>& T_odom_base,
                                  const std::vector<SessionTie>& ties,
                                  const PoseGraphConfig& graph);

// Adds `session` (its entries already in the map frame, their keyframes into `info`'s
// trajectory) to `map` as a new session; an entry within `same_segment_m` of an older session's
// entry of its class takes that entry's segment id. Returns how many did.
size_t joinSession(TargetMap& map, const TargetMap& session, MapSession info,
                   double same_segment_m);

}  // namespace semsegmap
