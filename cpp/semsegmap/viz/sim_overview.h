// Pictures of the simulator: the bird's-eye view of the world with the four runs (like the
// paper's neighbourhood figure), and a contact sheet of one frame's sensors.
#pragma once

#include <filesystem>

#include "semsegmap/sim/simulator.h"

namespace semsegmap::viz {

// Top-down view coloured by class, shaded by height, with S0 (blue), S1 (green), S2 (red) and
// S3 (yellow) drawn over it. Written as PNG (atomically).
void writeSimOverview(const sim::WorldConfig& world, const std::filesystem::path& png,
                      double metres_per_pixel = 0.5);

// Frame `frame_index` of `run`: the three cameras under sunny and sunrise light, the label
// images, and the LiDAR range image.
void writeCameraContactSheet(const sim::WorldConfig& world, sim::Run run, size_t frame_index,
                             const std::filesystem::path& png);

}  // namespace semsegmap::viz
