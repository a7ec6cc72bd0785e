// The pipeline's three jobs (paper section III-D) as functions over a frame source: build a
// target map from a mapping run, localize a run against a target map, and (pipeline/slam.h)
// close loops while mapping. The apps only parse arguments and write files around these.
#pragma once

#include <algorithm>
#include <functional>
#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include "semsegmap/core/stop_token.h"
#include "semsegmap/pipeline/map_parameters.h"
#include "semsegmap/pipeline/map_tiles.h"
#include "semsegmap/pipeline/pipeline.h"

namespace semsegmap {

struct RunOptions {
  size_t max_frames = 0;                                    // 0: all
  std::function<void(size_t done, size_t total)> progress;  // optional
  // Checked before each frame: once asked, no further frame starts and the run ends with the
  // frames done (RunStats::interrupted). The caller's, so Ctrl-C handling stays the program's.
  StopToken stop;
  // Run on every frame before enrichment: the network, LiDAR odometry (front_end_stages.h).
  FrontEndStages stages;
  // The frames a run reads of `source`: the first max_frames, or all.
  size_t frameCount(const FrameSource& source) const { return framesToRead(source, max_frames); }
};

// Calls process(frame) on the run's frames in order (at most options.max_frames), with progress
// after each; options.stop is checked before each, so a frame started is always finished. True
// when every frame was processed, false when the stop request ended the loop early.
bool feedFrames(FrameSource& source, const RunOptions& options,
                const std::function<void(const Frame&)>& process);

struct RunStats {
  size_t frames = 0;
  StageTimes total;  // summed over frames; the pipeline alone, not reading or simulating data
  // RunOptions::stop ended the run before its last frame: `frames` are the frames done.
  bool interrupted = false;
  // What the segmentation network did, when the run's stages had one.
  std::optional<LabelingStats> labelling;
  double fps() const { return total.total() > 0 ? 1000.0 * frames / total.total() : 0.0; }
};

struct MappingRun {
  TargetMap map;
  // The poses the map was built with, one per frame: MapSegment::keyframe indexes them.
  std::vector<Pose> trajectory;
  size_t segments = 0;              // finished segments before removing duplicates
  size_t earlier_observations = 0;  // kept beside them (target_map.earlier_observations_apart_m)
  size_t duplicates_removed = 0;    // of either
  RunStats stats;
};

// Maps a run frame by frame, with poses from ground truth or odometry (for the loop-closed
// trajectory, see runSlam). Keeps config.target_map.max_points_per_segment picture points per
// segment. Frame by frame so that several configurations can share one rendered frame.
class MappingSession {
 public:
  MappingSession(const PipelineConfig& config, const DatasetInfo& info, PoseSource poses,
                 std::shared_ptr<Describer> describer, const FrontEndStages& stages = {});
  void process(const Frame& frame);
  MappingRun finish();  // once, after the last frame
  // The map of the segments finished so far, without those still in the local map (finish()
  // adds them): what a robot mapping live saves on request (docs/ros.md).
  TargetMap mapSoFar() const { return builder_.build(); }
  // The segments whose earlier observations the session holds until they finish
  // (target_map.earlier_observations_apart_m): each is still in the local map.
  std::vector<SegmentId> segmentsWithEarlierObservations() const;
  const Pipeline& pipeline() const { return pipeline_; }
  // The poses of the frames so far (MappingRun::trajectory).
  const std::vector<Pose>& trajectory() const { return run_.trajectory; }

 private:
  void add(const std::vector<Segment>& segments, const std::vector<Eigen::VectorXf>& d);
  void keepEarlierObservations(const FrameResult& r);
  void forgetVanishedSegments();
  void keepScanContext(const Frame& frame, const Pose& T_local_base);
  struct KeptObservation {
    MapSegment segment;
    Eigen::VectorXf descriptor;
  };
  struct SegmentViews {
    std::vector<KeptObservation> kept;                // each `apart` from the others
    KeptObservation latest;                           // the segment's last observation so far
    Eigen::Vector3f since = Eigen::Vector3f::Zero();  // centroid of the last kept, or the first
  };
  void keep(std::vector<KeptObservation>& kept, KeptObservation observation) const;
  // The frame (index into the run's trajectory) whose pose places what is added now: a merged
  // session's segments follow their frame's corrected pose (pipeline/session_merge.h).
  uint32_t currentKeyframe() const {
    return static_cast<uint32_t>(run_.trajectory.empty() ? 0 : run_.trajectory.size() - 1);
  }
  PipelineConfig config_;
  Pipeline pipeline_;
  TargetMapBuilder builder_;
  Pose T_base_lidar_;
  std::optional<Eigen::Vector3d> last_scan_context_;  // where the last one was made
  MappingRun run_;
  // Per segment still in the local map, the earlier observations the map keeps
  // (target_map.earlier_observations_apart_m).
  std::unordered_map<SegmentId, SegmentViews> earlier_;
};

MappingRun runMapping(FrameSource& source, const PipelineConfig& config, PoseSource poses,
                      std::shared_ptr<Describer> describer, const RunOptions& options = {});

// Which segments gave a localization: the local map's, the latest scan's own
// (localization.latest_scan_fallback_m), or those of a relocalization against the whole map
// (localization.relocalization).
enum class LocalizationPath { kLocalMap, kLatestScan, kRelocalization, kScanContext };
const char* localizationPathName(LocalizationPath path);  // "local-map", ...

struct LocalizationRecord {
  size_t frame_index = 0;              // in the run, from 0 (Frame::index)
  std::optional<size_t> frame_number;  // the dataset's own (Frame::number), when it has one
  std::optional<double> timestamp_s;   // the data's time; nothing when it has none (FrameStamp)
  Pose T_map_base = Pose::Identity();  // T_map_local * T_local_base
  int inliers = 0;
  size_t candidates = 0;
  // Ground truth, when the dataset has it; errors compare it with T_map_base, so they assume a
  // target map built in the world frame (with ground-truth poses).
  std::optional<Pose> T_world_base;
  double translation_error_m = 0.0, rotation_error_deg = 0.0;  // only with ground truth
  // Matched centroids: the local one carried into the map by the estimate, and the target's.
  std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>> matches;
  // Pose refinement (localization.refinement): whether it moved T_map_base, and by how much.
  bool refined = false;
  double refinement_correction_m = 0.0;
  LocalizationPath path = LocalizationPath::kLocalMap;
  // Relocalization: the share of the local points that lie on the map's after registration.
  std::optional<double> registration_fitness;
  // The pose's uncertainty from its own evidence: 6 x 6 in the map frame, ROS order (x, y, z,
  // roll, pitch, yaw; localize/pose_covariance.h).
  Covariance6 covariance = Covariance6::Identity();
  // A relocalization whose scan registers nearly as well at another place
  // (relocalization.ambiguity_ratio): recorded with its status, never used as a pose, never
  // counted as a localization (LocalizationRun::ambiguous).
  bool ambiguous = false;
  std::optional<double> runner_up_fitness;  // of a relocalization: the best place elsewhere
};

struct LocalizationRun {
  std::vector<LocalizationRecord> localizations;
  // Relocalizations that fit two places (LocalizationRecord::ambiguous): kept apart, so that
  // every count of localizations stays one of poses a robot may act on.
  std::vector<LocalizationRecord> ambiguous;
  std::vector<Pose> trajectory_gt;    // empty without ground truth
  std::vector<Pose> trajectory_odom;  // the robot's own estimate, in its odometry frame
  std::vector<FrameStamp> frames;     // per frame run (as trajectory_odom): the data's names
  double distance_m = 0.0;            // driven, by odometry
  // The odometry was the ground truth itself (DatasetInfo): the errors say how the run does
  // with perfect odometry, and the summaries mark them so.
  bool odometry_is_ground_truth = false;
  RunStats stats;
};

// Localizes the local segment map (built on odometry, as a robot would) against `map` every
// config.localization.every_n_frames frames. Checks first that the describer's descriptors are
// the map's (kind, dimension and model) and that the map was built with the configuration's
// enrichment, local-map and segmentation settings (`settings`: refuse or warn).
class LocalizationSession {
 public:
  LocalizationSession(const PipelineConfig& config, const DatasetInfo& info,
                      std::shared_ptr<const TargetMap> map, std::shared_ptr<Describer> describer,
                      MapSettingsCheck settings = MapSettingsCheck::kRefuse,
                      const FrontEndStages& stages = {});
  // The localization found on this frame, if any (also added to run().localizations).
  std::optional<LocalizationRecord> process(const Frame& frame);
  // A robot that localizes for days keeps no history: with `keep` false, run() holds only the
  // latest frame's poses and stamp and the latest localization, beside the counts and the
  // distance; a record lives on where the caller puts it (process() returns it). Offline runs keep
  // everything (the default): their outputs are written from it.
  void keepHistory(bool keep) { keep_history_ = keep; }
  // Where the robot is known to be (a GNSS fix, the last saved pose, a user's guess): a
  // relocalization then only searches the map within the prior's radius. Nothing: everywhere.
  void setPrior(std::optional<RelocalizationPrior> prior) { prior_ = std::move(prior); }
  // A map served in tiles (map_tiles.h): the session's map holds those around tiles->centre();
  // once the robot has localized, every tiles->reloadAfterM() metres it moves (by the pose in
  // the map its last localization gave, carried on by odometry) the tiles around it are asked
  // for and added to the localizer. Tiles are never dropped: a drive's map only grows.
  void followTiles(std::shared_ptr<MapTileSource> tiles) { tiles_ = std::move(tiles); }
  const LocalizationRun& run() const { return run_; }
  LocalizationRun take() {
    run_.stats.labelling = pipeline_.labeling();
    return std::move(run_);
  }
  // One scan on its own, as a robot that wakes up has it: the frame through a fresh front end
  // (the network, no odometry: the scan's frame is its local map's) and the first frame's path of
  // `process` with relocalization on, whatever the config says; the map must store points. The
  // session's run and state are untouched. `prior` as setPrior's. The record, or nothing found.
  std::optional<LocalizationRecord> relocalize(
      const Frame& frame, const std::optional<RelocalizationPrior>& prior = std::nullopt) const;

 private:
  // One localization attempt on a pipeline's local segments.
  struct Attempt {
    std::optional<Localization> found;
    std::optional<Refinement> refined;
    std::optional<double> fitness;  // of a relocalization's registration check
    bool by_scan_context = false;   // the relocalization's pose was the scan context's
    bool ambiguous = false;         // the relocalization's scan fits another place too
    std::optional<double> runner_up_fitness;
    // What the pose's covariance comes from: the last registration that moved or checked it
    // (with its inflation), or nothing: the matched centroids.
    std::optional<RegistrationEvidence> evidence;
    LocalSegmentQuery query;
  };
  Attempt attempt(const Pipeline& pipeline) const;
  Attempt attemptRelocalization(const Pipeline& pipeline, const Frame& frame,
                                const Pose& T_local_base,
                                const std::optional<RelocalizationPrior>& prior) const;
  void requireRegistration(const Pipeline& pipeline, const Frame& frame, const Pose& T_local_base,
                           Attempt& a) const;
  bool jumps(const Attempt& a, const Pose& T_local_base) const;
  std::optional<ScanContextQuery> scanContextQuery(const Frame& frame,
                                                   const Pose& T_local_base) const;
  struct Outcome {
    Attempt attempt;
    LocalizationPath path = LocalizationPath::kLocalMap;
    Pose T_map_base = Pose::Identity();
  };
  // `relocalize`: try the relocalization path when the other paths find nothing.
  void forgetHistory();
  Outcome localizeFrame(const Pipeline& pipeline, const Frame& frame, const Pose& T_local_base,
                        double moved, bool relocalize,
                        const std::optional<RelocalizationPrior>& prior) const;
  Refinement refine(const Pipeline& pipeline, const Localization& l,
                    const LocalSegmentQuery& q) const;
  LocalizationRecord recordOf(const Frame& frame, const Outcome& o) const;
  PipelineConfig config_;
  DatasetInfo info_;
  std::shared_ptr<Describer> describer_;
  FrontEndStages stages_;
  Localizer localizer_;
  Pipeline pipeline_;
  std::shared_ptr<MapTileSource> tiles_;
  std::optional<Pose> T_map_local_;  // from the last localization
  void followRobot(const Pose& T_local_base);
  LocalizationRun run_;
  size_t frames_ = 0;
  bool keep_history_ = true;
  double localized_at_m_ = -1.0;  // run_.distance_m at the last localization; < 0: none yet
  std::optional<RelocalizationPrior> prior_;
};

LocalizationRun runLocalization(FrameSource& source, const PipelineConfig& config,
                                std::shared_ptr<const TargetMap> map,
                                std::shared_ptr<Describer> describer,
                                const RunOptions& options = {},
                                MapSettingsCheck settings = MapSettingsCheck::kRefuse,
                                std::optional<RelocalizationPrior> prior = std::nullopt,
                                std::shared_ptr<MapTileSource> tiles = nullptr);

struct LocalizationSummary {
  size_t localizations = 0;
  size_t with_ground_truth = 0;  // localizations whose frame had a ground-truth pose
  // Unknown (empty) rather than zero, which would read as "none within 1 m" or as perfect: the
  // counts when a localization had no ground truth, the means when none had.
  std::optional<size_t> below_1m, below_5m;
  std::optional<double> mean_translation_error_m, mean_rotation_error_deg;
  // How honest the covariances are, over the localizations with ground truth (position, 3
  // degrees of freedom): the share whose Mahalanobis distance is at most 3 (ideal 0.97), the
  // mean NEES (ideal 3), and the median position sigma (the root of the mean of the three
  // variances), so that a huge covariance cannot pass for an honest one.
  std::optional<double> share_mahalanobis_within_3, mean_nees, median_sigma_m;
};
LocalizationSummary summarize(const std::vector<LocalizationRecord>& records);
// The covariance fields of a summary from each pose's covariance and position error (the
// reference may be other than the record's ground truth: eval revisits' registered one).
void summarizeCovariances(
    const std::vector<std::pair<const Covariance6*, Eigen::Vector3d>>& covariance_and_error,
    LocalizationSummary& s);
// The same, and the counts unknown too when the run had no ground truth at all (no
// localization then does not mean none was wrong).
LocalizationSummary summarize(const LocalizationRun& run);

}  // namespace semsegmap
