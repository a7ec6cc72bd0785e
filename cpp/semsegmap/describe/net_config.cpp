// validateNetConfig (net_config.h): plain values, so that model files are checked in a build
// without libtorch too.
#include <stdexcept>
#include <string>

#include "semsegmap/describe/net_config.h"

namespace semsegmap {

namespace {

void requireRange(const char* field, int value, int lo, int hi) {
  if (value < lo || value > hi) {
    throw std::invalid_argument("NetConfig." + std::string(field) + " = " + std::to_string(value) +
                                ": expected " + std::to_string(lo) + ".." + std::to_string(hi));
  }
}

void requireMultiple(const char* field, int value, int of) {
  if (value % of != 0) {
    throw std::invalid_argument("NetConfig." + std::string(field) + " = " + std::to_string(value) +
                                ": expected a multiple of " + std::to_string(of));
  }
}

bool isLearned(DescriptorKind kind) {
  return kind == DescriptorKind::kSemSegMapNet || kind == DescriptorKind::kSegMapCnn;
}

}  // namespace

void validateNetConfig(const NetConfig& config) {
  if (!isLearned(config.kind)) {
    throw std::invalid_argument("NetConfig.kind = " + descriptorName(config.kind) +
                                ": expected segmap-cnn or semsegmap-net");
  }
  requireRange("descriptor_dim", config.descriptor_dim, 1, 4096);
  // Set abstraction takes num_points / 4 and / 16 centres.
  requireRange("num_points", config.num_points, 64, 1 << 16);
  requireRange("sa1_divisor", config.sa1_divisor, 1, 64);
  requireRange("sa2_divisor", config.sa2_divisor, config.sa1_divisor, 1024);
  requireMultiple("num_points", config.num_points, config.sa2_divisor);
  requireMultiple("num_points", config.num_points, config.sa1_divisor);
  requireRange("sa_neighbours", config.sa_neighbours, 1, 256);
  if (!(config.sa1_radius > 0.0f && config.sa1_radius < 10.0f && config.sa2_radius > 0.0f &&
        config.sa2_radius < 10.0f))
    throw std::invalid_argument("NetConfig.sa1_radius/sa2_radius: expected 0 < radius < 10");
  requireRange("num_classes", config.num_classes, 1, 1024);
  // segmap-cnn halves the grid three times.
  requireRange("grid_xy", config.grid_xy, 8, 256);
  requireMultiple("grid_xy", config.grid_xy, 8);
  requireRange("grid_z", config.grid_z, 8, 256);
  requireMultiple("grid_z", config.grid_z, 8);
  // The decoder doubles from 2^3.
  requireRange("recon_grid", config.recon_grid, 4, 128);
  if ((config.recon_grid & (config.recon_grid - 1)) != 0) {
    throw std::invalid_argument("NetConfig.recon_grid = " + std::to_string(config.recon_grid) +
                                ": expected a power of two");
  }
  requireRange("pointnet_width", config.pointnet_width, 1, 1024);
  requireRange("cnn_width", config.cnn_width, 1, 1024);
}

}  // namespace semsegmap
