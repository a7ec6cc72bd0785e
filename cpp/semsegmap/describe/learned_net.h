// The learned descriptors as libtorch modules, shared by inference (describe/) and training
// (learn/): `semsegmap-net` (PointNet++ on the coloured points + a small 3D CNN on a 3x3x3 grid
// of class histograms + the normalisation scale) and `segmap-cnn` (SegMap's CNN on a 32x32x16
// occupancy grid aligned by 2-D PCA yaw). Both also decode a voxel grid from the descriptor
// (reconstruction loss), and are trained with the same triplet loss.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "semsegmap/core/enriched_point.h"
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
};

// Throws std::invalid_argument naming the field when a value is out of range (e.g. a grid size
// the decoder cannot reach by doubling).
void validateNetConfig(const NetConfig& config);

// Everything the networks take, made from segment points. Built by makeNetInput, consumed by
// forward(); `target_occupancy` is what the decoder is trained to reproduce.
struct NetInput {
  torch::Tensor points;            // semsegmap-net: [B, num_points, 6] xyz (unit scale) + hsv-ish
  torch::Tensor class_grid;        // semsegmap-net: [B, num_classes, 3, 3, 3] normalised histograms
  torch::Tensor scale;             // [B, 1] or [B, 3]: the normalisation scale(s)
  torch::Tensor occupancy;         // segmap-cnn input: [B, 1, grid_xy, grid_xy, grid_z]
  torch::Tensor target_occupancy;  // decoder target, [B, 1, D, D, D] (or the cnn's own grid)
  torch::Tensor n_points;          // [B] float: points in each segment before subsampling
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

// Model files: a header (magic, format version, descriptor kind, NetConfig, fingerprint) and
// the weights. load throws std::runtime_error naming the file when it is missing, truncated,
// corrupt or of another kind than `expected` (when given).
void saveNet(const std::filesystem::path& path, DescriptorNetImpl& net);
std::shared_ptr<DescriptorNetImpl> loadNet(const std::filesystem::path& path,
                                           std::optional<DescriptorKind> expected = std::nullopt);
// Fingerprint of the weights (hex of a hash over every parameter and buffer), and of the
// NetConfig, which changes the descriptors of the same weights (num_points) too.
std::string netFingerprint(DescriptorNetImpl& net);

}  // namespace semsegmap
