// segmap-cnn: SegMap's descriptor CNN (Dubé et al., IJRR 2019) as the geometry-only baseline:
// a yaw-aligned binary occupancy grid through 3D convolutions and a dense layer that also takes
// the grid's 3 scale factors, into the descriptor; a decoder reconstructs the grid.
#pragma once

#include <torch/torch.h>

#include "semsegmap/describe/learned_net.h"

namespace semsegmap {

// With w = NetConfig::cnn_width (default 32: SegMap's widths) on the grid_xy x grid_xy x grid_z
// grid (G):
//   conv 3^3 stride 2, 1 -> w     (G/2)        SegMap: conv 32, max pool 2
//   conv 3^3 stride 2, w -> 2w    (G/4)        SegMap: conv 64, max pool 2
//   conv 3^3 stride 2, 2w -> 2w   (G/8)        SegMap: conv 64
//   dense 512 over the flattened grid + the 3 log scale factors, ReLU
//   dense 512 -> descriptor_dim
//   decoder  dense dim -> 2w x G/8, transposed conv x3 back to G, conv 3^3 -> 1 (logits)
// Stride-2 convolutions instead of full-resolution convolutions followed by max pooling: SegMap's
// layout costs ~165 M multiply-adds a segment, ~6 ms on one core here, far from the budget of
// 1000 segments/s on 2 cores; this one costs ~20 M (~0.6 ms). The dense layer over the flattened
// grid is a convolution whose kernel covers the whole grid, for oneDNN's speed (see
// semsegmap_net.h); the encoder's convolutions go through convOnOneDnn.
class SegMapCnnImpl : public DescriptorNetImpl {
 public:
  explicit SegMapCnnImpl(const NetConfig& config);
  NetOutput forward(const NetInput& input) override;
  torch::Tensor encode(const NetInput& input) override;
  const NetConfig& config() const override { return config_; }

 private:
  NetConfig config_;
  torch::nn::ModuleList encoder_{nullptr};  // of Conv3d, each followed by ReLU
  torch::nn::Conv3d dense_grid_{nullptr};
  torch::nn::Linear dense_scale_{nullptr};
  torch::nn::Linear descriptor_{nullptr};
  torch::nn::Linear decoder_seed_{nullptr};
  torch::nn::Sequential decoder_{nullptr};
};

}  // namespace semsegmap
