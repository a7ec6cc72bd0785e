// Reads the pipeline configuration (config/semsegmap.yaml, config/segmap.yaml) into the plain
// config structs. The one place that knows YAML keys; unknown keys and wrong types are errors.
#pragma once

#include <filesystem>

#include "semsegmap/odometry/lidar_odometry.h"
#include "semsegmap/pipeline/pipeline_config.h"
#include "semsegmap/semantics/segmentation_network.h"

namespace semsegmap {

// Throws std::runtime_error "<file>: <section.key>: <what was wrong>".
PipelineConfig loadPipelineConfig(const std::filesystem::path& path);

// The `odometry:` section of the same file (LiDAR odometry, odometry/lidar_odometry.h): the
// defaults when it has none. Same errors.
OdometryConfig loadOdometryConfig(const std::filesystem::path& path);

// The `semantics:` section (the segmentation network, semantics/segmentation_network.h): the
// model and a class map file relative to the config file; no model when the section is absent.
SemanticsConfig loadSemanticsConfig(const std::filesystem::path& path);

}  // namespace semsegmap
