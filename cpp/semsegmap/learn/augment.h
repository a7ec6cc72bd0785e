// Training augmentation of segment observations (paper section III-C): geometric variations
// (rotation, jitter, scale, missing points or sections) and visual ones (colour shifts, wrong
// class labels), so that the descriptor learns what survives another viewpoint, another light
// and another segmentation. Pure functions: a new cloud out, the input untouched.
#pragma once

#include <random>

#include <Eigen/Core>

#include "semsegmap/core/enriched_point.h"

namespace semsegmap {

struct AugmentConfig {
  // The local map of a localization run is yawed against the target map by whatever the
  // odometry drifted, so the descriptor must not care about yaw at all: full turns.
  double max_yaw_rad = 3.14159265358979323846;
  double jitter_sigma_m = 0.02;           // a fifth of a voxel
  double max_scale_shift = 0.05;          // uniform scale in [1 - s, 1 + s]
  double max_drop_fraction = 0.2;         // random point drop, fraction in [0, max]
  double section_cut_probability = 0.5;   // a random plane cuts away part of the segment
  double max_cut_fraction = 0.3;          // ... up to this share of the points
  double max_hue_shift = 0.05;            // hue += [-x, x], cyclic
  double max_sv_scale_shift = 0.2;        // saturation and value *= [1 - x, 1 + x]
  double max_wrong_class_fraction = 0.1;  // share of the points given another class
  // A network's errors come in regions, not salt (sim/label_noise.h): with this probability a
  // planar section of up to max_confused_fraction of the points takes the class a network
  // confuses its own with (cls::confusionPartner; thin objects the class behind them). 0 keeps
  // the random draws, and so the models, of the recipe before it.
  double confused_section_probability = 0.0;
  double max_confused_fraction = 0.5;
  // One shipped model must also serve a robot without a camera (no colour) or without a
  // segmentation network (no classes), and there every point of a segment lacks them, not a
  // few: with this probability, drawn separately for each, an observation loses all its colour
  // or all its classes. 0 keeps the draws of the recipe before it.
  double modality_dropout_probability = 0.0;
  // A camera that covers only part of the LiDAR (one front camera on a 360-degree scanner) sees
  // part of a segment at the edge of its picture: with this probability the points beyond a
  // vertical plane (the frustum's edge), up to max_unobserved_fraction of them, lose colour and
  // class. 0 keeps the draws of the recipe before it.
  double partial_coverage_probability = 0.0;
  double max_unobserved_fraction = 0.9;
  int num_classes = 15;  // wrong classes are drawn from 1 .. num_classes - 1
};

Eigen::Vector3f centroidOf(const EnrichedCloud& cloud);

// Yaw (about the vertical axis through the centroid).
EnrichedCloud rotateYaw(const EnrichedCloud& cloud, double yaw_rad);
// Uniform scale about the centroid.
EnrichedCloud scaleAboutCentroid(const EnrichedCloud& cloud, double scale);
// Gaussian noise of sigma_m on each coordinate.
EnrichedCloud jitterPoints(const EnrichedCloud& cloud, double sigma_m, std::mt19937& rng);
// Each point is dropped with probability `fraction`; at least one point survives.
EnrichedCloud dropPoints(const EnrichedCloud& cloud, double fraction, std::mt19937& rng);
// Removes the points with normal . (p - centroid) > offset_m (the far side of a plane).
EnrichedCloud cutByPlane(const EnrichedCloud& cloud, const Eigen::Vector3f& normal,
                         double offset_m);
// A plane of random direction, placed so that about `fraction` of the points are cut away;
// at least one point survives.
EnrichedCloud cutSection(const EnrichedCloud& cloud, double fraction, std::mt19937& rng);
// Hue shifted cyclically in [0, 1), saturation and value scaled and clamped to [0, 1]; points
// without colour keep theirs.
EnrichedCloud shiftColor(const EnrichedCloud& cloud, double hue_shift, double saturation_scale,
                         double value_scale);
// Each point gets, with probability `fraction`, a class other than its own in 1..num_classes-1.
EnrichedCloud relabelPoints(const EnrichedCloud& cloud, double fraction, int num_classes,
                            std::mt19937& rng);

// A plane of random direction, placed as in cutSection; the points beyond it take the class a
// network confuses theirs with (one partner choice for the whole section), thin objects a
// building or vegetation behind them. Classes without a partner keep theirs.
EnrichedCloud confuseSection(const EnrichedCloud& cloud, double fraction, std::mt19937& rng);

// Every point without colour (grey, has_color false) when drop_color, without a class
// (unobserved, has_class false) when drop_classes: the observation as a sensor without that
// modality gives it.
EnrichedCloud dropModalities(const EnrichedCloud& cloud, bool drop_color, bool drop_classes);

// A vertical plane of random horizontal direction, placed so that about `fraction` of the
// points lie beyond it; those lose colour and class (unobserved), as beyond a camera's frustum.
// At least one point stays observed.
EnrichedCloud unobserveSection(const EnrichedCloud& cloud, double fraction, std::mt19937& rng);

// All of the above with random strengths within `config`.
EnrichedCloud augment(const EnrichedCloud& cloud, const AugmentConfig& config, std::mt19937& rng);

}  // namespace semsegmap
