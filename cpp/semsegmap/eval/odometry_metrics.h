// How good an odometry is against ground truth: the KITTI odometry benchmark's relative error
// (computed as its devkit, evaluate_odometry.cpp, computes it) and the absolute trajectory error.
#pragma once

#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

#include "semsegmap/core/pose.h"
#include "semsegmap/graph/trajectory.h"

namespace semsegmap {

// One segment of the KITTI evaluation: from first_frame to the first frame more than length_m
// further along the ground truth.
struct KittiSegment {
  size_t first_frame = 0, last_frame = 0;
  double length_m = 0.0;
  double translation_error = 0.0;  // metres per metre
  double rotation_error_rad_per_m = 0.0;
};

struct KittiLengthError {
  double length_m = 0.0;
  size_t segments = 0;
  double translation_percent = 0.0;
  double rotation_deg_per_100m = 0.0;
};

struct KittiRelativeError {
  std::vector<KittiSegment> segments;
  std::vector<KittiLengthError> by_length;  // the lengths that have segments
  // The means over all segments (the benchmark's numbers); 0 when there is no segment (a
  // trajectory shorter than the shortest length).
  double translation_percent = 0.0;
  double rotation_deg_per_100m = 0.0;
};

// The devkit's rules: the segment lengths 100, 200, ..., 800 m of ground-truth path; a segment
// starts at every 10th frame and ends at the first frame whose travelled distance exceeds the
// start's by more than the length; its error is inv(estimate delta) * ground-truth delta,
// translation norm and rotation angle each divided by the length. estimate and ground_truth
// pair by index (same length, else std::invalid_argument).
KittiRelativeError kittiRelativeError(const std::vector<Pose>& estimate,
                                      const std::vector<Pose>& ground_truth,
                                      const std::vector<double>& lengths_m = {100, 200, 300, 400,
                                                                              500, 600, 700, 800},
                                      size_t step_frames = 10);

nlohmann::ordered_json toJson(const KittiRelativeError& error);
nlohmann::ordered_json toJson(const TrajectoryError& error);

}  // namespace semsegmap
