// semsegmap-net (paper section III-C, figure 2): a PointNet++ backbone on the coloured points,
// a small 3D CNN on the 3x3x3 grid of class histograms and the normalisation scale, joined by a
// linear layer into the descriptor; a 3D transposed-convolution decoder reconstructs the
// segment's occupancy from the descriptor.
#pragma once

#include <torch/torch.h>

#include "semsegmap/describe/learned_net.h"

namespace semsegmap {

// `conv` applied to x on oneDNN whatever the batch size (same result and autograd as
// conv->forward): torch's own dispatch sends 1x1 kernels at batch < 16 on one thread, and small
// inputs at batch 1, to its reference path, 3 to 10 times slower here. Zero padding only.
torch::Tensor convOnOneDnn(torch::nn::Conv2dImpl& conv, const torch::Tensor& x);
torch::Tensor convOnOneDnn(torch::nn::Conv3dImpl& conv, const torch::Tensor& x);

// Widths with w = NetConfig::pointnet_width and N = num_points (features: xyz + 3 colour):
//   SA1  N/4 centres, radius 0.2, 16 neighbours, shared MLP 6 -> w -> w -> 2w, max
//   SA2  N/16 centres, radius 0.4, 16 neighbours, MLP 2w+3 -> 2w -> 2w -> 4w, max
//   (the defaults of NetConfig::sa1_divisor, sa1_radius, sa2_divisor, sa2_radius, sa_neighbours)
//   SA3  all points, MLP 4w+3 -> 4w -> 8w, max                                    -> 8w
//   classes  conv 1^3 C -> w, conv 2^3 -> 2w (2^3 cells), conv 2^3 -> 4w (1 cell)  -> 4w
//   scale    log(scale / 1 m), linear 1 -> w                                       -> w
//   head     linear 13w -> descriptor_dim
//   decoder  linear dim -> 4w x 2^3, transposed convs (stride 2, channels halved, >= 8) up to
//            recon_grid^3, conv 3^3 -> 1 (logits)
// Radii are in the unit-scale frame (the farthest point at distance 1), as in PointNet++ on
// ModelNet; the neighbours' offsets are divided by the radius so each level sees [-1, 1].
// Size: the defaults N = 512, w = 16 and 16 neighbours (PointNet++: 1024 points, 32 and 64
// neighbours, widths 64 to 1024) cost ~4 M multiply-adds and ~0.7 ms a segment on one core here,
// inference, batched: 4 times the budget of 300 segments/s on 2 cores, kept as headroom for the
// cores shared with the rest of the pipeline and for the 90-minute training budget. N = 1024
// costs 2.5x (farthest point sampling is quadratic), N = 2048 (the paper) 8x; w = 32 2x.
// The shared MLPs are 1x1 convolutions rather than matrix products because torch's CPU matrix
// product goes to the system BLAS (reference BLAS on Debian: ~2 GFLOP/s) while convolutions go
// to oneDNN (~10x faster), by convOnOneDnn above. No batch normalisation: a descriptor must not
// depend on the batch it was computed in, and training and inference then run the same function.
class SemSegMapNetImpl : public DescriptorNetImpl {
 public:
  explicit SemSegMapNetImpl(const NetConfig& config);
  NetOutput forward(const NetInput& input) override;
  torch::Tensor encode(const NetInput& input) override;
  const NetConfig& config() const override { return config_; }

 private:
  struct SetAbstraction {
    int centres = 0;  // 0: group all points
    float radius = 0;
    int neighbours = 0;
    torch::nn::ModuleList mlp{nullptr};  // of Conv2d 1x1, each followed by ReLU
  };
  // xyz [B, n, 3], features [B, n, c] -> centres' xyz [B, m, 3] and features [B, m, c'].
  std::pair<torch::Tensor, torch::Tensor> abstract(SetAbstraction& level, const torch::Tensor& xyz,
                                                   const torch::Tensor& features);

  NetConfig config_;
  SetAbstraction sa1_, sa2_, sa3_;
  torch::nn::ModuleList class_cnn_{nullptr};  // of Conv3d, each followed by ReLU
  torch::nn::Linear scale_embedding_{nullptr};
  torch::nn::Linear head_{nullptr};
  torch::nn::Linear decoder_seed_{nullptr};
  torch::nn::Sequential decoder_{nullptr};
};

}  // namespace semsegmap
