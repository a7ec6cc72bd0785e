#include "semsegmap/describe/segmap_cnn.h"

#include "semsegmap/describe/net_input.h"
#include "semsegmap/describe/semsegmap_net.h"

namespace semsegmap {

namespace {

namespace nn = torch::nn;

nn::Conv3d downConv(int in, int out) {
  return nn::Conv3d(nn::Conv3dOptions(in, out, 3).stride(2).padding(1));
}

nn::ConvTranspose3d upConv(int in, int out) {
  return nn::ConvTranspose3d(nn::ConvTranspose3dOptions(in, out, 2).stride(2));
}

}  // namespace

SegMapCnnImpl::SegMapCnnImpl(const NetConfig& config) : config_(config) {
  validateNetConfig(config_);
  const int w = config_.cnn_width;
  const int64_t gxy = config_.grid_xy / 8, gz = config_.grid_z / 8;
  encoder_ = register_module(
      "encoder", nn::ModuleList(downConv(1, w), downConv(w, 2 * w), downConv(2 * w, 2 * w)));
  dense_grid_ =
      register_module("dense_grid", nn::Conv3d(nn::Conv3dOptions(2 * w, 512, {gxy, gxy, gz})));
  // No bias: dense_grid has one, and the two add up to one dense layer over [grid, scales].
  dense_scale_ = register_module("dense_scale", nn::Linear(nn::LinearOptions(3, 512).bias(false)));
  descriptor_ = register_module("descriptor", nn::Linear(512, config_.descriptor_dim));

  decoder_seed_ =
      register_module("decoder_seed", nn::Linear(config_.descriptor_dim, 2 * w * gxy * gxy * gz));
  decoder_ =
      register_module("decoder", nn::Sequential(upConv(2 * w, 2 * w), nn::ReLU(), upConv(2 * w, w),
                                                nn::ReLU(), upConv(w, w), nn::ReLU(),
                                                nn::Conv3d(nn::Conv3dOptions(w, 1, 3).padding(1))));
}

torch::Tensor SegMapCnnImpl::encode(const NetInput& input) {
  torch::Tensor x = input.occupancy;
  for (const std::shared_ptr<nn::Module>& layer : *encoder_) {
    x = convOnOneDnn(*std::dynamic_pointer_cast<nn::Conv3dImpl>(layer), x).relu_();
  }
  const torch::Tensor grid = convOnOneDnn(*dense_grid_, x).flatten(1);
  const torch::Tensor min_extent =
      torch::tensor({kSegMapMinExtentM[0], kSegMapMinExtentM[1], kSegMapMinExtentM[2]});
  // log(extent / minimum) is 0 for every small segment and grows slowly for large ones.
  const torch::Tensor scales = torch::log(input.scale / min_extent).clamp_min(0.0);
  return descriptor_->forward(torch::relu(grid + dense_scale_->forward(scales)));
}

NetOutput SegMapCnnImpl::forward(const NetInput& input) {
  NetOutput out;
  out.descriptor = encode(input);
  const int64_t b = out.descriptor.size(0);
  const torch::Tensor seed =
      torch::relu(decoder_seed_->forward(out.descriptor))
          .view({b, -1, config_.grid_xy / 8, config_.grid_xy / 8, config_.grid_z / 8});
  out.reconstruction = decoder_->forward(seed);
  return out;
}

}  // namespace semsegmap
