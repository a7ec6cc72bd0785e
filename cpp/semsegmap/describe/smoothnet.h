// 3dsmoothnet: 3DSmoothNet's local descriptors (Gojcic et al., CVPR 2019) aggregated into a
// segment descriptor as a bag of visual words, the way the SemSegMap paper compared it (its
// descriptor figure). Written from the paper's description, not from its code.
#pragma once

#include <torch/torch.h>

#include "semsegmap/describe/learned_net.h"

namespace semsegmap {

// A keypoint's SDV grid (describe/smoothnet_input.h, G = NetConfig::smoothnet_voxels cells a
// side) through a small 3D CNN, with w = smoothnet_width:
//   conv 3^3 1 -> w (G), conv 3^3 stride 2 w -> 2w (G/2), conv 3^3 2w -> 2w,
//   conv 3^3 stride 2 2w -> 4w (G/4), conv G/4^3 4w -> 4w (the whole grid), each with ReLU,
//   linear 4w -> smoothnet_local_dim, unit length                       -> the local descriptor
// The paper's network (six convolutions of 32 to 128 channels, batch normalisation) costs ~15
// times these ~7 M multiply-adds a keypoint; a segment is described at smoothnet_keypoints of
// them, and 3DSmoothNet here is a baseline for retrieval, so the smaller one. No batch
// normalisation, for the reason of semsegmap_net.h: a descriptor must not depend on its batch.
//
// The segment descriptor: each keypoint's local descriptor votes for its nearest visual word
// (the `words` buffer, descriptor_dim x local_dim, k-means centres fitted by the training
// command), and the descriptor is the share of the keypoints of each word.
class SmoothNetImpl : public DescriptorNetImpl {
 public:
  explicit SmoothNetImpl(const NetConfig& config);
  // input.sdv [B * keypoints, 1, G, G, G] -> the bag of words [B, descriptor_dim].
  torch::Tensor encode(const NetInput& input) override;
  // As encode; no decoder (reconstruction is left undefined).
  NetOutput forward(const NetInput& input) override;
  const NetConfig& config() const override { return config_; }

  // SDV grids [N, 1, G, G, G] -> local descriptors [N, local_dim] of unit length.
  torch::Tensor local(const torch::Tensor& sdv);
  // Local descriptors [N, local_dim] -> the index of each one's nearest word [N].
  torch::Tensor nearestWord(const torch::Tensor& local_descriptors) const;
  // Sets the visual words (k-means centres, [descriptor_dim, local_dim]).
  void setWords(const torch::Tensor& words);
  const torch::Tensor& words() const { return words_; }

 private:
  torch::Tensor localSlice(const torch::Tensor& sdv);

  NetConfig config_;
  torch::nn::ModuleList cnn_{nullptr};  // of Conv3d, each followed by ReLU
  torch::nn::Linear local_{nullptr};
  torch::Tensor words_;
};

}  // namespace semsegmap
