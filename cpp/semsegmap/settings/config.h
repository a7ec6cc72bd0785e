// Reads the pipeline configuration (config/semsegmap.yaml, config/segmap.yaml) into the plain
// config structs, through the setting table (pipeline/setting_table.h): a key is its member path,
// old keys are read as their new ones (with one note a file), unknown keys, wrong types and values
// out of their limits are errors.
#pragma once

#include <filesystem>

#include "semsegmap/odometry/lidar_odometry.h"
#include "semsegmap/pipeline/pipeline_config.h"
#include "semsegmap/pipeline/setting_table.h"
#include "semsegmap/semantics/segmentation_network.h"

namespace semsegmap {

// Throws std::runtime_error "<file>: <section.key>: <what was wrong>".
PipelineConfig loadPipelineConfig(const std::filesystem::path& path);

// Every setting of the file: the pipeline's, the odometry's and the semantics' (as the three
// loaders read them). Same errors.
Settings loadSettings(const std::filesystem::path& path);

// The `odometry:` section of the same file (LiDAR odometry, odometry/lidar_odometry.h): the
// defaults when it has none. Same errors.
OdometryConfig loadOdometryConfig(const std::filesystem::path& path);

// The `semantics:` section (the segmentation network, semantics/segmentation_network.h): the
// model and a class map file relative to the config file; no model when the section is absent.
SemanticsConfig loadSemanticsConfig(const std::filesystem::path& path);

}  // namespace semsegmap
