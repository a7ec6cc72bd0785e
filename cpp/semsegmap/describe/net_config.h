// What a learned descriptor network is, without torch: its configuration and, once trained, its
// weights as plain values. Model files (artefacts/model_file.h) store exactly this.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "semsegmap/describe/descriptor.h"

namespace semsegmap {

struct NetConfig {
  DescriptorKind kind = DescriptorKind::kSemSegMapNet;
  int descriptor_dim = 64;
  int num_points = 512;  // semsegmap-net: random subsample (paper: 2048; semsegmap_net.h)
  int num_classes = 16;  // class ids >= this count into the last bin
  int grid_xy = 32;      // segmap-cnn occupancy grid
  int grid_z = 16;
  int recon_grid = 16;  // decoder output: recon_grid^3 occupancy (semsegmap-net)
  // Channels of the first layer; the later ones are multiples (semsegmap_net.h, segmap_cnn.h).
  // Chosen for the inference budget on a 2-core CPU (bench/bench_describe.cpp).
  int pointnet_width = 16;  // semsegmap-net
  int cnn_width = 32;       // segmap-cnn: SegMap's 32, 64, 64
  // semsegmap-net's two set abstraction levels: num_points / divisor centres, each grouping at
  // most sa_neighbours points within its radius (in the unit-scale frame of the input). Model
  // files before format version 2 did not record these; every one was trained with these values.
  int sa1_divisor = 4;
  float sa1_radius = 0.2f;
  int sa2_divisor = 16;
  float sa2_radius = 0.4f;
  int sa_neighbours = 16;
  // The modalities the network sees (semsegmap-net). Off, every point enters without colour or
  // as of class unknown: a model trained so serves a LiDAR without a camera, and sees the same
  // input from data that has them. Model files before format version 3 used both.
  bool use_color = true;
  bool use_classes = true;
  // 3dsmoothnet (describe/smoothnet.h): descriptor_dim is its number of visual words. Model
  // files before format version 4 hold no such model.
  int smoothnet_keypoints = 32;   // random keypoints a segment is described at
  float smoothnet_radius = 1.0f;  // metres: the local frame's support, half the grid's side
  int smoothnet_voxels = 16;      // the SDV grid's cells a side (the paper's 16)
  int smoothnet_local_dim = 32;   // a keypoint's descriptor (the paper's 32)
  int smoothnet_width = 8;        // channels of the first convolution
};

// Throws std::invalid_argument naming the field when a value is out of range (e.g. a grid size
// the decoder cannot reach by doubling). The ranges are those a network on this project's CPU
// budget can have, so that a corrupt model header is refused before anything is built.
void validateNetConfig(const NetConfig& config);

// The parameters of the network a (valid) configuration gives, by name and shape in the module's
// registration order, as semsegmap_net.cpp and segmap_cnn.cpp build them: a model file is checked
// against these before its network is built (tests/test_learned_net.cpp compares the two).
struct TensorShape {
  std::string name;
  std::vector<int64_t> shape;
  size_t numel() const;
};
std::vector<TensorShape> netTensorShapes(const NetConfig& config);

struct ModelTensor {
  std::string name;  // the module's parameter or buffer name
  std::vector<int64_t> shape;
  std::vector<float> values;  // row-major, product(shape) values
};

// A trained network: configuration, weights in the module's registration order, and the
// fingerprint of both (describe/learned_net.h, netFingerprint).
struct Model {
  NetConfig config;
  std::string fingerprint;  // 16 hex digits
  std::vector<ModelTensor> tensors;
};

}  // namespace semsegmap
