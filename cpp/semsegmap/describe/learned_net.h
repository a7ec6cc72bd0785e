// The learned descriptors as libtorch modules, shared by inference (describe/) and training
// (learn/): `semsegmap-net` (PointNet++ on the coloured points + a small 3D CNN on a 3x3x3 grid
// of class histograms + the normalisation scale) and `segmap-cnn` (SegMap's CNN on a 32x32x16
// occupancy grid aligned by 2-D PCA yaw). Both also decode a voxel grid from the descriptor
// (reconstruction loss), and are trained with the same triplet loss. `3dsmoothnet`
// (smoothnet.h) describes keypoints and bags them into words; it is trained on corresponding
// points instead (learn/smoothnet_trainer.h).
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "semsegmap/core/enriched_point.h"
#include "semsegmap/describe/descriptor.h"
#include "semsegmap/describe/net_config.h"

namespace semsegmap {

// Everything the networks take, made from segment points. Built by makeNetInput, consumed by
// forward(); `target_occupancy` is what the decoder is trained to reproduce.
struct NetInput {
  torch::Tensor points;            // semsegmap-net: [B, num_points, 6] xyz (unit scale) + hsv-ish
  torch::Tensor class_grid;        // semsegmap-net: [B, num_classes, 3, 3, 3] normalised histograms
  torch::Tensor scale;             // [B, 1] or [B, 3]: the normalisation scale(s)
  torch::Tensor occupancy;         // segmap-cnn input: [B, 1, grid_xy, grid_xy, grid_z]
  torch::Tensor target_occupancy;  // decoder target, [B, 1, D, D, D] (or the cnn's own grid)
  torch::Tensor n_points;          // [B] float: points in each segment before subsampling
  torch::Tensor sdv;               // 3dsmoothnet: [B * smoothnet_keypoints, 1, G, G, G] SDV grids
  int64_t keypoints = 0;           // 3dsmoothnet: the smoothnet_keypoints the grids were made at
};

struct NetOutput {
  torch::Tensor descriptor;      // [B, descriptor_dim]
  torch::Tensor reconstruction;  // logits, same shape as NetInput::target_occupancy
};

// Random subsampling uses `rng`; pass a fixed seed for repeatable inference.
NetInput makeNetInput(const NetConfig& config, const std::vector<const EnrichedCloud*>& segments,
                      std::mt19937& rng);
// The subsample of segment i is a pure function of its point set and salts[i] (net_input.h):
// with one salt for all, a segment gets the same input wherever it sits in the batch and
// whatever the order of its points. Throws std::invalid_argument on an empty or null segment.
NetInput makeNetInput(const NetConfig& config, const std::vector<const EnrichedCloud*>& segments,
                      const std::vector<uint64_t>& salts);

class DescriptorNetImpl : public torch::nn::Module {
 public:
  virtual NetOutput forward(const NetInput& input) = 0;
  // The descriptor alone, without the decoder (inference).
  virtual torch::Tensor encode(const NetInput& input) = 0;
  virtual const NetConfig& config() const = 0;
};

// Freshly initialised weights (torch's global RNG: torch::manual_seed for repeatability).
// Throws std::invalid_argument for a hand-made kind or an invalid config.
std::shared_ptr<DescriptorNetImpl> makeNet(const NetConfig& config);

// The paper's triplet loss, batched: max(m + sigma * D(A,P) - D(A,N), 0) with Euclidean D and
// sigma = points(P) / points(A); mean over the batch.
torch::Tensor tripletLoss(const torch::Tensor& anchor, const torch::Tensor& positive,
                          const torch::Tensor& negative, const torch::Tensor& sigma,
                          double margin = 0.4);

// The plain value of a trained network (artefacts/model_file.h reads and writes it): modelOf copies
// the weights out, netFromModel builds the network of model.config and copies them in, checking
// every name and shape and the fingerprint (std::runtime_error saying what does not match).
Model modelOf(DescriptorNetImpl& net);
std::shared_ptr<DescriptorNetImpl> netFromModel(const Model& model);
// Fingerprint of the weights (hex of a hash over every parameter and buffer), and of the
// NetConfig, which changes the descriptors of the same weights (num_points) too.
std::string netFingerprint(DescriptorNetImpl& net);

}  // namespace semsegmap
