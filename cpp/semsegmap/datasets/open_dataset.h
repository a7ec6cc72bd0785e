// The --dataset SPEC of every subcommand, turned into a FrameSource:
//   DIR                    a dataset directory in the project's format (docs/dataset-format.md)
//   kitti-raw:PATH         a KITTI raw drive
//   semantickitti:PATH     a SemanticKITTI sequence
//   nclt:PATH              an NCLT session
//   sim:KEY=VALUE,...      the built-in simulator, streamed without touching the disk; keys:
//                          world (seed, default 1), run (S0..S3, default S2), condition,
//                          traffic (seed), frames (maximum), preset (full|small|tiny), cameras
//                          (0|1); a build without the simulator (SEMSEGMAP_WITH_SIM=OFF)
//                          says so in one line
#pragma once

#include <memory>
#include <string>

#include "semsegmap/core/frame_source.h"

namespace semsegmap {

// Throws std::runtime_error / std::invalid_argument naming the spec and what was wrong.
std::unique_ptr<FrameSource> openDataset(const std::string& spec);

}  // namespace semsegmap
