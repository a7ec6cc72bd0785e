// validateNetConfig (net_config.h): plain values, so that model files are checked in a build
// without libtorch too.
#include <algorithm>
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

void validateSmoothNet(const NetConfig& config) {
  requireRange("smoothnet_keypoints", config.smoothnet_keypoints, 1, 1024);
  // The network halves the grid twice and then covers it with one kernel.
  requireRange("smoothnet_voxels", config.smoothnet_voxels, 8, 64);
  requireMultiple("smoothnet_voxels", config.smoothnet_voxels, 4);
  requireRange("smoothnet_local_dim", config.smoothnet_local_dim, 2, 1024);
  requireRange("smoothnet_width", config.smoothnet_width, 1, 256);
  requireRange("descriptor_dim (visual words)", config.descriptor_dim, 2, 1024);
  if (!(config.smoothnet_radius > 0.0f && config.smoothnet_radius < 100.0f))
    throw std::invalid_argument("NetConfig.smoothnet_radius: expected 0 < radius < 100 m");
}

}  // namespace

void validateNetConfig(const NetConfig& config) {
  if (!isLearnedDescriptor(config.kind)) {
    throw std::invalid_argument("NetConfig.kind = " + descriptorName(config.kind) +
                                ": expected segmap-cnn, semsegmap-net or 3dsmoothnet");
  }
  if (config.kind == DescriptorKind::kSmoothNetBow) validateSmoothNet(config);
  requireRange("descriptor_dim", config.descriptor_dim, 1, 1024);
  // Set abstraction takes num_points / 4 and / 16 centres (the paper: 2048 points).
  requireRange("num_points", config.num_points, 64, 16384);
  requireRange("sa1_divisor", config.sa1_divisor, 1, 64);
  requireRange("sa2_divisor", config.sa2_divisor, config.sa1_divisor, 1024);
  requireMultiple("num_points", config.num_points, config.sa2_divisor);
  requireMultiple("num_points", config.num_points, config.sa1_divisor);
  requireRange("sa_neighbours", config.sa_neighbours, 1, 256);
  if (!(config.sa1_radius > 0.0f && config.sa1_radius < 10.0f && config.sa2_radius > 0.0f &&
        config.sa2_radius < 10.0f))
    throw std::invalid_argument("NetConfig.sa1_radius/sa2_radius: expected 0 < radius < 10");
  requireRange("num_classes", config.num_classes, 1, 256);
  // segmap-cnn halves the grid three times (SegMap: 32 x 32 x 16).
  requireRange("grid_xy", config.grid_xy, 8, 128);
  requireMultiple("grid_xy", config.grid_xy, 8);
  requireRange("grid_z", config.grid_z, 8, 128);
  requireMultiple("grid_z", config.grid_z, 8);
  // The decoder doubles from 2^3; its output is recon_grid^3 a segment.
  requireRange("recon_grid", config.recon_grid, 4, 64);
  if ((config.recon_grid & (config.recon_grid - 1)) != 0) {
    throw std::invalid_argument("NetConfig.recon_grid = " + std::to_string(config.recon_grid) +
                                ": expected a power of two");
  }
  requireRange("pointnet_width", config.pointnet_width, 1, 256);
  requireRange("cnn_width", config.cnn_width, 1, 256);
}

size_t TensorShape::numel() const {
  size_t n = 1;
  for (const int64_t s : shape) n *= static_cast<size_t>(s);
  return n;
}

namespace {

using Shapes = std::vector<TensorShape>;

// A layer's weight of `shape` and its bias of shape[bias_dim] (transposed convolutions keep
// their output channels second).
void addLayer(Shapes& out, const std::string& name, std::vector<int64_t> shape, int bias_dim = 0,
              bool bias = true) {
  const int64_t channels = shape[static_cast<size_t>(bias_dim)];
  out.push_back({name + ".weight", std::move(shape)});
  if (bias) out.push_back({name + ".bias", {channels}});
}

void addPointwiseMlp(Shapes& out, const std::string& name, const std::vector<int64_t>& channels) {
  for (size_t i = 1; i < channels.size(); ++i)
    addLayer(out, name + "." + std::to_string(i - 1), {channels[i], channels[i - 1], 1, 1});
}

Shapes semsegmapNetShapes(const NetConfig& c) {
  const int64_t w = c.pointnet_width, dim = c.descriptor_dim;
  Shapes out;
  addPointwiseMlp(out, "sa1", {6, w, w, 2 * w});
  addPointwiseMlp(out, "sa2", {2 * w + 3, 2 * w, 2 * w, 4 * w});
  addPointwiseMlp(out, "sa3", {4 * w + 3, 4 * w, 8 * w});
  addLayer(out, "class_cnn.0", {w, c.num_classes, 1, 1, 1});
  addLayer(out, "class_cnn.1", {2 * w, w, 2, 2, 2});
  addLayer(out, "class_cnn.2", {4 * w, 2 * w, 2, 2, 2});
  addLayer(out, "scale_embedding", {w, 1});
  addLayer(out, "head", {dim, 13 * w});
  addLayer(out, "decoder_seed", {4 * w * 8, dim});
  int64_t channels = 4 * w;
  int index = 0;  // every transposed convolution is followed by a ReLU in the sequence
  for (int size = 2; size < c.recon_grid; size *= 2, index += 2) {
    const int64_t next = std::max<int64_t>(channels / 2, 8);
    addLayer(out, "decoder." + std::to_string(index), {channels, next, 2, 2, 2}, 1);
    channels = next;
  }
  addLayer(out, "decoder." + std::to_string(index), {1, channels, 3, 3, 3});
  return out;
}

Shapes segmapCnnShapes(const NetConfig& c) {
  const int64_t w = c.cnn_width, dim = c.descriptor_dim;
  const int64_t gxy = c.grid_xy / 8, gz = c.grid_z / 8;
  Shapes out;
  addLayer(out, "encoder.0", {w, 1, 3, 3, 3});
  addLayer(out, "encoder.1", {2 * w, w, 3, 3, 3});
  addLayer(out, "encoder.2", {2 * w, 2 * w, 3, 3, 3});
  addLayer(out, "dense_grid", {512, 2 * w, gxy, gxy, gz});
  addLayer(out, "dense_scale", {512, 3}, 0, false);
  addLayer(out, "descriptor", {dim, 512});
  addLayer(out, "decoder_seed", {2 * w * gxy * gxy * gz, dim});
  addLayer(out, "decoder.0", {2 * w, 2 * w, 2, 2, 2}, 1);
  addLayer(out, "decoder.2", {2 * w, w, 2, 2, 2}, 1);
  addLayer(out, "decoder.4", {w, w, 2, 2, 2}, 1);
  addLayer(out, "decoder.6", {1, w, 3, 3, 3});
  return out;
}

Shapes smoothNetShapes(const NetConfig& c) {
  const int64_t w = c.smoothnet_width, g = c.smoothnet_voxels / 4;
  Shapes out;
  addLayer(out, "cnn.0", {w, 1, 3, 3, 3});
  addLayer(out, "cnn.1", {2 * w, w, 3, 3, 3});
  addLayer(out, "cnn.2", {2 * w, 2 * w, 3, 3, 3});
  addLayer(out, "cnn.3", {4 * w, 2 * w, 3, 3, 3});
  addLayer(out, "cnn.4", {4 * w, 4 * w, g, g, g});
  addLayer(out, "local", {c.smoothnet_local_dim, 4 * w});
  out.push_back({"words", {c.descriptor_dim, c.smoothnet_local_dim}});  // a buffer, not trained
  return out;
}

}  // namespace

std::vector<TensorShape> netTensorShapes(const NetConfig& config) {
  validateNetConfig(config);
  switch (config.kind) {
    case DescriptorKind::kSemSegMapNet:
      return semsegmapNetShapes(config);
    case DescriptorKind::kSmoothNetBow:
      return smoothNetShapes(config);
    default:
      return segmapCnnShapes(config);
  }
}

}  // namespace semsegmap
