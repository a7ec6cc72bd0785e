// Bird's-eye picture of a localization run, like the paper's first figure: the target map's
// segments in grey, the query trajectory, every localization as a dot coloured by its error, and
// the matched segment pairs of one localization as lines.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/pose.h"

namespace semsegmap::viz {

struct LocalizationPicture {
  std::string title;
  std::vector<Eigen::Vector3f> map_points;  // segment points when the map kept them
  std::vector<Eigen::Vector3f> map_centroids;
  std::vector<Pose> trajectory;  // the query run (ground truth when known)
  // Whether the run had ground truth: else the legend has no error colours (every dot is of the
  // unknown-error colour) and the trajectory is the odometry, in its own frame.
  bool has_ground_truth = true;
  // Estimated positions and their translation errors (negative: unknown).
  std::vector<std::pair<Eigen::Vector3d, double>> localizations;
  // The highlighted localization: its position and its matches (local centroid carried into the
  // map by the estimate, target centroid).
  Eigen::Vector3d highlight = Eigen::Vector3d::Zero();
  std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>> matches;
};

void writeLocalizationPng(const std::filesystem::path& png, const LocalizationPicture& picture);

}  // namespace semsegmap::viz
