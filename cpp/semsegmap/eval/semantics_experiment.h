// How well the camera's classes land on the LiDAR points (`semsegmap eval semantics`): the
// enriched points' classes, which come only from the cameras' label images (a network's or a
// label set's), against the dataset's per-point ground truth (SemanticKITTI's labels, the
// simulator's), per frame and after the local map's voxel votes.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/core/json.h"
#include "semsegmap/core/stop_token.h"
#include "semsegmap/eval/confusion_matrix.h"
#include "semsegmap/pipeline/pipeline_config.h"

namespace semsegmap {

// Counts over the points whose ground truth is a class (truth unknown, SemanticKITTI's
// unlabeled and outlier, is left out of every count).
struct SemanticScores {
  size_t points = 0;      // points with a ground-truth class
  size_t classified = 0;  // of them, points a camera gave a class (has_class, or a voxel's votes)
  size_t correct = 0;     // of those, points whose class is the ground truth's
  ConfusionMatrix confusion;  // of the classified points

  void add(ClassId truth, bool has_class, ClassId predicted);
  SemanticScores& operator+=(const SemanticScores& o);
  double accuracy() const;         // correct / classified; 0 when none
  double classifiedShare() const;  // classified / points
  double correctShare() const;     // correct / points: of all points, the correctly classed
  // TP / (TP + FP + FN) of a class; -1 when the class is in neither truth nor prediction.
  double iou(ClassId id) const;
};

struct SemanticsFrame {
  size_t frame = 0;  // the dataset's frame index
  SemanticScores per_frame, after_votes;
};

struct SemanticsEvaluation {
  std::string dataset;
  ClassTable classes;
  std::vector<SemanticsFrame> frames;
  SemanticScores per_frame, after_votes;  // summed over the frames
  // The map segments (every finished segment's last observation, as the map keeps it) and those
  // with a class: at least one of the observation's points has one.
  size_t segments = 0, segments_with_class = 0;
  // SemanticsEvalConfig::stop ended it early: the scores are those of `frames`, the frames done.
  bool interrupted = false;
};

struct SemanticsEvalConfig {
  PipelineConfig pipeline;  // enrichment, local map (voxel size, radius) and segmentation
  size_t max_frames = 0;    // 0: all
  StopToken stop;           // checked before each frame (Ctrl-C in the CLI)
};

using SemanticsProgress = std::function<void(size_t done, size_t total)>;

// Reads every frame of `source`; its point labels are the truth only: they are taken off the
// frame before enrichment, so that the classes measured come from the cameras alone. Votes are
// fused in a local map of the config's voxel size and radius that keeps every classified point
// (no class is filtered out, ground and cars included); a point's class after the votes is its
// voxel's majority. Poses: ground truth when the dataset has it, else odometry. Throws
// std::runtime_error naming the dataset when it has no cameras, no per-point ground-truth
// classes, or no poses, and naming the frame when a frame has no ground truth or no label image
// in any camera.
SemanticsEvaluation evaluateSemantics(FrameSource& source, const SemanticsEvalConfig& config,
                                      const SemanticsProgress& progress = {});

nlohmann::ordered_json toJson(const SemanticsEvaluation& e);
// The short table `eval semantics` prints: per frame and after votes, accuracy and shares, then
// the per-class IoU.
std::string semanticsTable(const SemanticsEvaluation& e);

}  // namespace semsegmap
