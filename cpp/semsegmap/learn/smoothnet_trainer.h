// Training of 3dsmoothnet (describe/smoothnet.h) on simulated ground truth, as the 3DSmoothNet
// paper trains its network: corresponding points of two observations of one object (the
// observations' points are in the map frame of the ground-truth poses, so a keypoint's
// counterpart is the other observation's nearest point) are positives, the batch's other
// keypoints negatives (a softmax over the batch rather than the paper's batch-hard margin loss,
// which collapsed here: smoothnet_trainer.cpp). Then the visual words: k-means (OpenCV's) over the
// local descriptors of keypoints of training observations, stored in the model.
#pragma once

#include <memory>

#include "semsegmap/describe/smoothnet.h"
#include "semsegmap/learn/trainer.h"
#include "semsegmap/learn/training_data.h"

namespace semsegmap {

struct SmoothNetTrainConfig {
  NetConfig net;  // kind 3dsmoothnet; descriptor_dim: the number of visual words (the paper's 16)
  // The shipped model's recipe (models/MODEL_CARD.md): about 10 minutes on 2 cores.
  int epochs = 20;
  size_t steps_per_epoch = 500;
  int batch_pairs = 64;  // corresponding keypoint pairs a step
  double learning_rate = 1e-3;
  // Of the softmax over a batch's keypoints (distances between unit-length descriptors / this).
  double temperature = 0.1;
  // A keypoint's counterpart: the other observation's nearest point, if within this (metres).
  double correspondence_m = 0.15;
  // Training observations whose keypoints the words are fitted to (the paper: a subset).
  size_t bow_observations = 800;
  double validation_fraction = 0.1;  // of the objects (splitByInstance)
  uint64_t split_seed = 1;
  size_t validation_pairs = 1000;  // fixed pairs of the validation objects, ranked every epoch
  size_t max_validation_queries = 2000;  // the segment retrieval at the end (validationAccuracy)
  int threads = 2;
  uint64_t seed = 1;
};

SmoothNetTrainConfig defaultSmoothNetTrainConfig();

struct SmoothNetTrainResult {
  // net: the best epoch's weights (by the validation pairs' top-1) with its words; null when
  // stopped before the first epoch ended. history: validation = keypoint retrieval among the
  // validation pairs (is a keypoint's counterpart its nearest descriptor?).
  TrainResult training;
  // Segment retrieval of the bag of words on the validation objects (validationAccuracy).
  RetrievalAccuracy segments;
  size_t word_keypoints = 0;  // local descriptors the words were fitted to
  double word_seconds = 0.0;
};

// Throws std::invalid_argument on a bad config, std::runtime_error when the data has no object
// seen twice or no corresponding keypoints. callbacks.best is not called: the model is complete
// only once its words are fitted, after the last epoch.
SmoothNetTrainResult trainSmoothNet(const TrainingSet& data, const SmoothNetTrainConfig& config,
                                    const TrainCallbacks& callbacks = {});

// Fits the visual words of `net` to the local descriptors of `keypoints` keypoints of each of
// `which` (k-means++, seeded): what trainSmoothNet does after its epochs. Returns the number of
// local descriptors. Throws std::runtime_error with fewer descriptors than words.
size_t fitVisualWords(SmoothNetImpl& net, const TrainingSet& data, const std::vector<size_t>& which,
                      uint64_t seed);

}  // namespace semsegmap
