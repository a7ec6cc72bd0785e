// Training of the learned descriptors (semsegmap-net, segmap-cnn) on simulated ground-truth
// associations: the paper's triplet loss with sigma = points(P) / points(A) plus the decoder's
// per-voxel reconstruction loss, Adam, augmented observations, random negatives during warm-up
// and then the hardest of a few, and the best epoch chosen by validation retrieval accuracy.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/stop_token.h"
#include "semsegmap/describe/learned_net.h"
#include "semsegmap/learn/augment.h"
#include "semsegmap/learn/training_data.h"

namespace semsegmap {

struct TrainConfig {
  NetConfig net;  // net.kind: kSemSegMapNet or kSegMapCnn
  int epochs = 12;
  int batch_size = 32;               // triplets a step (the network sees 3x as many observations)
  size_t anchors_per_epoch = 0;      // 0: every training observation that has a positive
  double learning_rate = 1e-3;       // Adam
  double learning_rate_decay = 1.0;  // multiplies the learning rate after every epoch
  double margin = 0.4;               // the paper's m
  double reconstruction_weight = 0.1;
  // Anchors of a batch that are decoded for the reconstruction loss (0: all). The decoder costs
  // more than the encoder, twenty times for segmap-cnn's 32x32x16 grid: a few anchors keep the
  // regularisation at a fraction of the time.
  int reconstruction_anchors = 0;
  // Of a positive pair, the observation with more points is the anchor, so that
  // sigma = points(P) / points(A) <= 1 weighs a pair by how complete its smaller half is: the
  // paper's heuristic against penalising pairs that share little. (Drawn the other way round, a
  // 100-point anchor with a 10000-point positive would weigh a hundred times the rest of its
  // batch.) The cap only trims what the augmentation's cuts and drops add to the ratio.
  double max_sigma = 1.0;
  int warmup_epochs = 1;  // random negatives; afterwards the hardest of the candidates below
  int hard_negative_candidates = 8;
  double validation_fraction = 0.1;      // of the instances
  uint64_t split_seed = 1;               // which instances are held out
  size_t max_validation_queries = 4000;  // random subset beyond (retrieval is quadratic)
  // Queries less complete than this are left out of the validation: below half of its final
  // points a segment is mostly a fragment that matches by luck, and the sigma weighting
  // deliberately trains for the more complete ones.
  double validation_min_completeness = 0.5;
  int threads = 2;    // torch::set_num_threads
  uint64_t seed = 1;  // weights, sampling, augmentation: the same seed gives the same model
  bool augment = true;
  AugmentConfig augmentation;
  // Distillation (used when trainDescriptor is given a teacher): the student is also pulled
  // towards the teacher's descriptor of the very observation it sees, weighted by this against
  // the triplet loss (the mean squared distance of the two 64-d descriptors). A LiDAR-only
  // student so learns from a colour-trained teacher what the teacher knows with colour and
  // classes, which the triplet loss on grey points alone does not teach it.
  double distillation_weight = 1.0;
  // The student starts from the teacher's weights (the same network; a LiDAR-only student then
  // starts as the teacher sees grey points) rather than from fresh ones.
  bool start_from_teacher = true;
};

// The recipe of the shipped models for `kind`: sized to train in well under 90 minutes on two
// cores, extraction of S1 included (models/MODEL_CARD.md).
TrainConfig defaultTrainConfig(DescriptorKind kind);

struct EpochStats {
  int epoch = 0;                                                     // from 1
  double loss = 0.0, triplet_loss = 0.0, reconstruction_loss = 0.0;  // means over the epoch
  double distillation_loss = 0.0;                                    // 0 without a teacher
  RetrievalAccuracy validation;
  double learning_rate = 0.0;
  double seconds = 0.0;  // training and validation
  bool best = false;     // the best so far (and saved)
};

struct TrainResult {
  // With the weights of the best epoch; null when interrupted before the first epoch ended.
  std::shared_ptr<DescriptorNetImpl> net;
  std::vector<EpochStats> history;  // the epochs completed
  int best_epoch = 0;
  size_t train_observations = 0, validation_observations = 0, anchors = 0;
  // TrainCallbacks::stop ended training early: the epoch in hand was dropped unvalidated, and
  // `net` is the best of the epochs completed.
  bool interrupted = false;
};

struct TrainCallbacks {
  // After every step: epoch (from 1), steps done in it, steps in it, mean loss so far.
  std::function<void(int, size_t, size_t, double)> step;
  std::function<void(const EpochStats&)> epoch;
  // Each time the best epoch improves, with the network in that state (e.g. to save it).
  std::function<void(DescriptorNetImpl&)> best;
  // Checked before each step (Ctrl-C in the CLI): a step started always finishes, the partial
  // epoch is dropped and training ends (TrainResult::interrupted).
  StopToken stop;
};

// Trains a new network on `data`. The best epoch is the one of highest validation top-1 (the
// lowest training loss when the validation half has no query). With a `teacher` (a trained
// network of the same kind and descriptor size, left unchanged), the loss also holds the
// distillation term of config.distillation_weight. Throws std::invalid_argument on a bad config
// or a teacher that does not fit and std::runtime_error when the data has no instance seen twice.
TrainResult trainDescriptor(const TrainingSet& data, const TrainConfig& config,
                            const TrainCallbacks& callbacks = {},
                            std::shared_ptr<DescriptorNetImpl> teacher = nullptr);

// Descriptors (one row each) of data.observations[which[i]], unaugmented, in eval mode; the
// subsampling of the points is seeded by `seed`.
Eigen::MatrixXf describeObservations(DescriptorNetImpl& net, const TrainingSet& data,
                                     const std::vector<size_t>& which, uint64_t seed,
                                     int batch_size = 64);

// Validation retrieval accuracy of `net`, as a localization would use the descriptor: the final
// (most complete) observation of every segment in `data` forms the database (the target map; the
// training landmarks are its distractors), and every earlier observation among `which` that has
// at least `min_completeness` of its segment's final points is a query that must find its
// landmark (landmarkLabels) there. Comparing every observation with every other instead would be
// trivial with several runs on one trajectory: the other condition's observation of a segment at
// the same frame has the same points, only other colours. At most `max_queries`, a fixed random
// subset.
RetrievalAccuracy validationAccuracy(DescriptorNetImpl& net, const TrainingSet& data,
                                     const std::vector<size_t>& which, uint64_t seed,
                                     size_t max_queries = 4000, double min_completeness = 0.5);

// Throws std::invalid_argument "teacher: ..." unless `teacher` describes in the student's space
// (config.net): the same kind of network and descriptor size.
void checkTeacher(const TrainConfig& config, DescriptorNetImpl& teacher);

struct Triplet {
  size_t anchor = 0, positive = 0, negative = 0;  // indices into TrainingSet::observations
};

// The training loss (triplet + weighted reconstruction) of `net` on fixed triplets, unaugmented,
// in eval mode and with subsampling seeded by config.seed: a yardstick that does not move with
// the sampling of the batches.
double evaluateTriplets(DescriptorNetImpl& net, const TrainingSet& data,
                        const std::vector<Triplet>& triplets, const TrainConfig& config);

}  // namespace semsegmap
