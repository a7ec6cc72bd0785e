// The configuration of the whole pipeline: one struct per stage, each with its defaults next to
// the code that uses it. settings/config.h reads it from YAML.
#pragma once

#include <string>

#include "semsegmap/enrich/enricher.h"
#include "semsegmap/graph/pose_graph.h"
#include "semsegmap/local_map/local_map.h"
#include "semsegmap/localize/localizer.h"
#include "semsegmap/localize/pose_covariance.h"
#include "semsegmap/localize/pose_refinement.h"
#include "semsegmap/localize/relocalizer.h"
#include "semsegmap/localize/target_map.h"
#include "semsegmap/segment/semantic_distance.h"

namespace semsegmap {

struct DescriptorConfig {
  std::string kind = "semsegmap-net";  // descriptorName(): semsegmap-net, segmap-cnn, eigen, fpfh
  std::string model;  // model file of a learned descriptor; in YAML relative to the config file
  int batch = 64;     // segments described per forward pass
  // Optional: the model taken instead for input with neither colour nor classes (a LiDAR
  // without a camera; pipeline/input_modalities.h).
  std::string model_lidar_only;
  // 3dsmoothnet: random keypoints a segment is described at (its bag of words' sample); 0: the
  // model's (train --keypoints). More keypoints give a steadier histogram for more time.
  int keypoints = 0;
};

struct LocalizationConfig {
  LocalizerConfig localizer;
  size_t every_n_frames = 1;  // query the target map every n-th frame
  // When the local map's segments do not localize and the latest scan lies at least this far
  // (by odometry) from the scan before, also try the segments of that scan alone, cut in a local
  // map of its own as a robot waking up there would cut them. Where scans lie far apart, the
  // local map also holds the places of the scans before, which cut the place differently from
  // the map (KITTI 00 sparse: scan 1576 with 1511 and 1538). It costs a second segmentation and
  // description of the scan, so scans close together (a LiDAR at 10 Hz) never pay it. 0: off.
  double latest_scan_fallback_m = 0.0;
  // Off by default: it needs a target map with segment points (target_map.
  // max_points_per_segment), which costs 6 bytes a point.
  RefinementConfig refinement;
  // When neither localizes: one scan against the whole map (localize/relocalizer.h).
  RelocalizationConfig relocalization;
  // The covariance every localization carries (localize/pose_covariance.h).
  PoseCovarianceConfig covariance;
};

struct LoopClosureConfig {
  // Segments finished within this many metres of driving before now are not loop candidates:
  // matching the robot against what it has just seen would only confirm odometry.
  double exclude_recent_m = 60.0;
  double min_travel_between_loops_m = 5.0;  // one loop edge per place, not one per frame
  // Odometry sigma 0.05 m / 0.005 rad, loop sigma 0.3 m / 0.02 rad.
  PoseGraphConfig graph{0.05, 0.005, 0.3, 0.02};
};

// A new session joining a map (pipeline/session_merge.h).
struct SessionMergeConfig {
  // The session's observation of a segment this near an older session's observation of the same
  // class (the one of nearest descriptor, when several are) is an observation of that segment,
  // not a new segment. Two sessions' final observations of one object differ by up to a metre
  // (the tiny world, tests/test_session_merge.cpp).
  double same_segment_m = 1.5;
  // Localizations against the map a session needs to join it; with fewer it stays separate.
  size_t min_localizations = 3;
};

struct PipelineConfig {
  EnrichmentConfig enrichment;
  LocalMapConfig local_map;
  SegmentationConfig segmentation;
  DescriptorConfig descriptor;
  LocalizationConfig localization;
  TargetMapBuilderConfig target_map;
  LoopClosureConfig loop_closure;
  SessionMergeConfig session_merge;
};

}  // namespace semsegmap
