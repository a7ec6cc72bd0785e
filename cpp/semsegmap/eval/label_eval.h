// How well a segmentation network labels pictures (`semsegmap eval labels`): its label images
// against a dataset's own (the simulator's perfect ones), pixel by pixel at the cameras'
// resolution: per-class IoU, mean IoU, pixel accuracy and the time a picture takes.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "semsegmap/core/class_table.h"
#include "semsegmap/core/json.h"
#include "semsegmap/core/stop_token.h"
#include "semsegmap/eval/confusion_matrix.h"
#include "semsegmap/semantics/segmentation_network.h"
#include "semsegmap/viz/label_comparison.h"

namespace semsegmap {

// Pixels of label images counted by (truth, predicted) class; pixels whose truth is unknown (0)
// are left out of every count.
class LabelScores {
 public:
  // Throws std::invalid_argument when the two differ in size or are not 1-channel.
  void add(const Image& truth, const Image& predicted);
  LabelScores& operator+=(const LabelScores& o);
  size_t truthPixels(ClassId c) const;  // labelled pixels whose truth is c
  size_t labelledPixels() const;        // pixels whose truth is a class
  double pixelAccuracy() const;         // correct / labelled; 0 when none
  double iou(ClassId c) const;          // TP / (TP + FP + FN); -1 without truth or prediction
  // Mean IoU over the classes with truth pixels (unknown left out), with or without sky.
  double meanIou(bool with_sky) const;
  std::vector<ClassId> truthClasses(bool with_sky) const;

 private:
  ConfusionMatrix confusion_;
};

struct LabelEvalConfig {
  SemanticsConfig semantics;  // the network (model, class map resolved as the config says)
  std::filesystem::path class_maps_dir;
  size_t every = 1;       // every N-th frame
  size_t max_frames = 0;  // of each dataset, 0: all
  size_t examples = 4;    // pictures drawn side by side, spread over the datasets
  StopToken stop;
};

struct LabelEvalDataset {
  std::string spec;
  size_t pictures = 0;
  LabelScores scores;
};

struct LabelEvaluation {
  std::string model;
  ClassTable classes = ClassTable::Default();
  std::vector<LabelEvalDataset> datasets;
  LabelScores scores;  // over every dataset
  size_t pictures = 0;
  double network_seconds = 0;  // in SegmentationNetwork::label, summed
  std::vector<viz::LabelComparison> examples;
  bool interrupted = false;
};

using LabelEvalProgress = std::function<void(const std::string& spec, size_t done, size_t total)>;

// Opens each spec (openDataset, without a network: its label images are the truth) and labels
// every camera picture of every N-th frame with the network. Throws std::runtime_error naming the
// dataset when it has no cameras or a picture has no label image.
LabelEvaluation evaluateLabels(const std::vector<std::string>& specs, const LabelEvalConfig& config,
                               const LabelEvalProgress& progress = {});

nlohmann::ordered_json toJson(const LabelEvaluation& e);
std::string labelsTable(const LabelEvaluation& e);  // per class IoU per dataset, then the means

}  // namespace semsegmap
