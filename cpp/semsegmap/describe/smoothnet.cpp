#include "semsegmap/describe/smoothnet.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "semsegmap/describe/semsegmap_net.h"

namespace semsegmap {

namespace {

namespace nn = torch::nn;

constexpr int64_t kSmoothNetSlice = 32;

nn::Conv3d conv(int in, int out, int kernel, int stride = 1, int padding = 0) {
  return nn::Conv3d(nn::Conv3dOptions(in, out, kernel).stride(stride).padding(padding));
}

}  // namespace

SmoothNetImpl::SmoothNetImpl(const NetConfig& config) : config_(config) {
  validateNetConfig(config_);
  if (config_.kind != DescriptorKind::kSmoothNetBow)
    throw std::invalid_argument("SmoothNetImpl: a " + descriptorName(config_.kind) + " config");
  const int w = config_.smoothnet_width, g = config_.smoothnet_voxels / 4;
  cnn_ = register_module("cnn", nn::ModuleList(conv(1, w, 3, 1, 1), conv(w, 2 * w, 3, 2, 1),
                                               conv(2 * w, 2 * w, 3, 1, 1),
                                               conv(2 * w, 4 * w, 3, 2, 1), conv(4 * w, 4 * w, g)));
  local_ = register_module("local", nn::Linear(4 * w, config_.smoothnet_local_dim));
  // Until the training command fits them, words on the axes (a model is never saved so).
  words_ = register_buffer(
      "words", torch::eye(config_.descriptor_dim, config_.smoothnet_local_dim, torch::kFloat));
}

torch::Tensor SmoothNetImpl::localSlice(const torch::Tensor& sdv) {
  // A grid sums to 1 over its G^3 cells: scaled to a mean of 1, its values are of the order the
  // initial weights expect (unscaled, every descriptor started as the biases' and stayed there).
  torch::Tensor x = sdv * static_cast<float>(sdv[0].numel());
  for (const std::shared_ptr<nn::Module>& layer : *cnn_)
    x = convOnOneDnn(*std::dynamic_pointer_cast<nn::Conv3dImpl>(layer), x).relu_();
  return torch::nn::functional::normalize(local_->forward(x.flatten(1)),
                                          torch::nn::functional::NormalizeFuncOptions().dim(1));
}

torch::Tensor SmoothNetImpl::local(const torch::Tensor& sdv) {
  // 32 grids at a time: the network takes 0.14 ms a grid in batches of 32 and 1.9 ms in batches
  // of 256 (BM_SmoothNetLocal), whose activations (8 channels of 16^3 a grid) leave the cache;
  // a describer's chunk of 64 segments holds 2048 grids.
  if (sdv.size(0) <= kSmoothNetSlice) return localSlice(sdv);
  std::vector<torch::Tensor> parts;
  for (int64_t start = 0; start < sdv.size(0); start += kSmoothNetSlice)
    parts.push_back(
        localSlice(sdv.slice(0, start, std::min(sdv.size(0), start + kSmoothNetSlice))));
  return torch::cat(parts);
}

torch::Tensor SmoothNetImpl::nearestWord(const torch::Tensor& local_descriptors) const {
  return torch::cdist(local_descriptors, words_).argmin(1);
}

void SmoothNetImpl::setWords(const torch::Tensor& words) {
  if (words.sizes() != words_.sizes())
    throw std::invalid_argument("SmoothNetImpl::setWords: expected [" +
                                std::to_string(words_.size(0)) + ", " +
                                std::to_string(words_.size(1)) + "] words");
  torch::NoGradGuard no_grad;
  words_.copy_(words);
}

torch::Tensor SmoothNetImpl::encode(const NetInput& input) {
  // The describer may sample more or fewer keypoints than the model was trained with
  // (descriptor.keypoints): the bag is a share of the keypoints either way.
  const int64_t k = input.keypoints > 0 ? input.keypoints : config_.smoothnet_keypoints;
  if (!input.sdv.defined() || input.sdv.size(0) % k != 0)
    throw std::invalid_argument("3dsmoothnet: the input holds no SDV grids of " +
                                std::to_string(k) + " keypoints a segment");
  const int64_t b = input.sdv.size(0) / k;
  const torch::Tensor words = nearestWord(local(input.sdv).detach());
  torch::Tensor bag = torch::zeros({b, config_.descriptor_dim});
  const torch::Tensor segment = torch::arange(b, torch::kLong).repeat_interleave(k);
  bag.index_put_({segment, words}, torch::ones({b * k}), /*accumulate=*/true);
  return bag / static_cast<float>(k);
}

NetOutput SmoothNetImpl::forward(const NetInput& input) {
  NetOutput out;
  out.descriptor = encode(input);
  return out;
}

}  // namespace semsegmap
