// Training data of the learned descriptors (paper section IV: trained only on simulated ground
// truth): every observation of every segment, with the ground-truth instance its points belong
// to, extracted by running the pipeline with ground-truth poses. Observations of one landmark
// (instance and class), from any run or lighting condition, are positives of each other.
#pragma once

#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/enriched_point.h"
#include "semsegmap/core/frame_source.h"
#include "semsegmap/core/stop_token.h"
#include "semsegmap/pipeline/pipeline_config.h"

namespace semsegmap {

// One segment observation, stored compactly: 27 bytes a point instead of sizeof(EnrichedPoint).
struct TrainingObservation {
  uint16_t instance = 0;                               // majority ground-truth instance
  ClassId majority_class = cls::kUnknown;              // of the segment's voxels
  uint16_t source = 0;                                 // index into TrainingSet::sources
  int64_t segment = 0;                                 // segment id within that source's run
  uint32_t n_points = 0;                               // before subsampling (the loss's sigma)
  uint32_t frame_index = 0;                            // the frame it was taken at
  float purity = 0.0f;                                 // share of the points of `instance`
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();  // map frame
  std::vector<float> xyzhsv;                           // 6 floats a stored point, map frame
  std::vector<ClassId> classes;                        // a class a stored point
  std::vector<uint8_t> modalities;                     // a stored point's kHasColor | kHasClass

  static constexpr uint8_t kHasColor = 1, kHasClass = 2;

  size_t size() const { return classes.size(); }
  EnrichedCloud cloud() const;  // instance_id of the points is `instance`
};

struct TrainingSet {
  std::vector<std::string> sources;  // dataset specs
  // Per source, the world its instance ids belong to (worldOf): runs through one world share
  // ids, so that their observations of an instance are positives; another world's ids are
  // unrelated objects. A missing entry means the source's own world.
  std::vector<std::string> source_worlds;
  std::vector<TrainingObservation> observations;
  // ExtractionConfig::stop ended the extraction early: the observations of the frames done, a
  // set that must not be cached as the whole one.
  bool interrupted = false;
};

struct ExtractionConfig {
  float min_purity = 0.8f;  // observations at or below this purity are ambiguous labels
  // Instances from DatasetInfo::first_transient_instance on are traffic and never kept: a parked
  // car whose points the cameras mislabelled as building survives the dynamic-class filter, but
  // it is no landmark, and another traffic seed puts other cars there.
  size_t max_frames = 0;  // per dataset; 0: all frames
  // Larger observations keep a random subset: memory stays bounded, and the networks see at
  // most a few thousand points anyway (semsegmap-net subsamples to NetConfig::num_points).
  size_t max_points_per_observation = 4096;
  uint64_t seed = 1;
  // Checked before each frame (Ctrl-C in the CLI): once asked, no further frame or dataset is
  // read and the set is marked interrupted. Not part of what the set is made from.
  StopToken stop;
};

// Called after each frame with (frames done, frames in this dataset, dataset index).
using ExtractionProgress = std::function<void(size_t, size_t, size_t)>;

// Runs the pipeline (ground-truth poses, keep_all_observation_points forced on) over `source`
// and appends the kept observations of every segment to `out`, tagged with `source_index`.
void appendObservations(FrameSource& source, uint16_t source_index, PipelineConfig pipeline,
                        const ExtractionConfig& config, TrainingSet& out,
                        const ExtractionProgress& progress = {});

// ---- Pairs, negatives and the validation split -------------------------------------------------

// The object an observation sees: a hash of its world and instance, one per observation.
std::vector<uint64_t> objectKeys(const TrainingSet& set);

// What a descriptor must find again: the observations of one object of one majority class (a
// tree's trunk and crown are one instance but two segments, never matched to each other).
// Dense labels 0..L-1, one per observation.
std::vector<int> landmarkLabels(const TrainingSet& set);

// Validation objects are chosen by a hash of the object key, never by observation, so that no
// object is seen in training and validation; an object goes to the same half whatever the data
// set it is in.
bool isValidationObject(uint64_t object_key, double validation_fraction, uint64_t seed);

struct TrainValSplit {
  std::vector<size_t> train, validation;  // indices into TrainingSet::observations
};
TrainValSplit splitByInstance(const TrainingSet& set, double validation_fraction, uint64_t seed);

// Positives (same landmark) and negatives (another object) among a subset of the observations
// (one half of the split).
class PairSampler {
 public:
  PairSampler(const TrainingSet& set, std::vector<size_t> subset);

  // Observations that have at least one positive: the anchors of an epoch.
  const std::vector<size_t>& anchors() const { return anchors_; }
  // Another observation of the same landmark (requires hasPositive).
  size_t positive(size_t anchor, std::mt19937& rng) const;
  bool hasPositive(size_t anchor) const;
  // An observation of another object, uniformly.
  size_t negative(size_t anchor, std::mt19937& rng) const;
  bool isPositive(size_t a, size_t b) const { return a != b && label_[a] == label_[b]; }
  bool isNegative(size_t a, size_t b) const { return object_[a] != object_[b]; }

 private:
  std::vector<size_t> subset_;
  std::vector<uint64_t> object_;              // per observation of the whole set
  std::vector<int> label_;                    // per observation of the whole set
  std::vector<std::vector<size_t>> members_;  // per label: its observations in the subset
  std::vector<size_t> anchors_;
};

// ---- Retrieval accuracy ------------------------------------------------------------------------

// The last kept observation of each segment (per source): the most complete one, which is what
// a target map holds.
std::vector<bool> finalObservations(const TrainingSet& set);

struct RetrievalAccuracy {
  double top1 = 0.0, top5 = 0.0;  // shares of the queries; 0 when there is no query
  size_t queries = 0;
};

// For each query row whose label is in the database: is the nearest database row (Euclidean)
// of its label (top-1), or one of the five nearest (top-5)? Queries without their label in the
// database are not counted.
RetrievalAccuracy retrievalAccuracy(const Eigen::MatrixXf& queries,
                                    const std::vector<int>& query_labels,
                                    const Eigen::MatrixXf& database,
                                    const std::vector<int>& database_labels);

}  // namespace semsegmap
