// Sampling and grouping run per segment on the CPU (pointnet_ops), in parallel over the batch;
// everything after the indices is ordinary differentiable torch.
#include "semsegmap/describe/semsegmap_net.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "semsegmap/describe/pointnet_ops.h"

namespace semsegmap {

namespace {

namespace nn = torch::nn;

// Shared MLP over [B, C, m, k] in channels-last layout: 1x1 convolutions, each followed by ReLU
// (also the last, before the max pool).
nn::ModuleList pointwiseMlp(const std::vector<int>& channels) {
  nn::ModuleList mlp;
  for (size_t i = 1; i < channels.size(); ++i) {
    mlp->push_back(nn::Conv2d(nn::Conv2dOptions(channels[i - 1], channels[i], 1)));
  }
  return mlp;
}

// In-place ReLU: out of place, torch runs it on channels-last tensors at a third of the
// convolutions' speed.
template <typename Conv>
torch::Tensor convReluStack(nn::ModuleList& layers, torch::Tensor x) {
  for (const std::shared_ptr<nn::Module>& layer : *layers) {
    x = convOnOneDnn(*std::dynamic_pointer_cast<Conv>(layer), x).relu_();
  }
  return x;
}

template <size_t D, typename Conv>
torch::Tensor convOnOneDnnImpl(Conv& conv, const torch::Tensor& x) {
  if (!at::hasMKLDNN()) return conv.forward(x);
  const auto& o = conv.options;
  const torch::ExpandingArray<D> padding = c10::get<torch::ExpandingArray<D>>(o.padding());
  const c10::optional<torch::Tensor> bias =
      conv.bias.defined() ? c10::optional<torch::Tensor>(conv.bias) : c10::nullopt;
  return at::mkldnn_convolution(x, conv.weight, bias, *padding, *o.stride(), *o.dilation(),
                                o.groups());
}

// Max over the k neighbours of y [B, c, m, k] (channels-last) -> [B, m, c]. Reducing the
// contiguous [B, m, k, c] view over k is ten times faster than amax(3) on the strided one.
torch::Tensor maxOverNeighbours(const torch::Tensor& y) {
  return y.permute({0, 2, 3, 1}).amax(2);
}

// Rows of x [B, n, c] picked per batch element by idx [B, ...] (int64) -> [B, ..., c].
torch::Tensor gatherRows(const torch::Tensor& x, const torch::Tensor& idx) {
  const int64_t b = x.size(0), n = x.size(1), c = x.size(2);
  const torch::Tensor offset = torch::arange(b, idx.options()).mul_(n).view({b, 1});
  const torch::Tensor flat = (idx.reshape({b, -1}) + offset).reshape({-1});
  std::vector<int64_t> sizes = idx.sizes().vec();
  sizes.push_back(c);
  return x.reshape({b * n, c}).index_select(0, flat).view(sizes);
}

// Farthest point sampling of m centres and ball query of k neighbours, per segment.
std::pair<torch::Tensor, torch::Tensor> sampleAndGroup(const torch::Tensor& xyz, int m,
                                                       float radius, int k) {
  const torch::Tensor points = xyz.detach().contiguous();
  const int64_t b = points.size(0);
  const int n = static_cast<int>(points.size(1));
  torch::Tensor centres = torch::empty({b, m}, torch::kLong);
  torch::Tensor neighbours = torch::empty({b, m, k}, torch::kLong);
  const float* p = points.data_ptr<float>();
  int64_t* centre_out = centres.data_ptr<int64_t>();
  int64_t* neighbour_out = neighbours.data_ptr<int64_t>();
  at::parallel_for(0, b, 1, [&](int64_t begin, int64_t end) {
    std::vector<int> centre_idx(static_cast<size_t>(m));
    std::vector<int> neighbour_idx(static_cast<size_t>(m) * k);
    std::vector<float> centre_xyz(static_cast<size_t>(m) * 3);
    std::vector<float> scratch;
    for (int64_t s = begin; s < end; ++s) {
      const float* cloud = p + s * n * 3;
      // Start at the first point: the inputs come in a canonical order (hashSubsample).
      farthestPointSample(cloud, n, m, 0, centre_idx.data(), scratch);
      for (int i = 0; i < m; ++i) {
        std::copy_n(cloud + 3 * centre_idx[i], 3, centre_xyz.data() + 3 * i);
      }
      ballQuery(cloud, n, centre_xyz.data(), m, radius, k, neighbour_idx.data());
      std::copy(centre_idx.begin(), centre_idx.end(), centre_out + s * m);
      std::copy(neighbour_idx.begin(), neighbour_idx.end(), neighbour_out + s * m * k);
    }
  });
  return {centres, neighbours};
}

}  // namespace

torch::Tensor convOnOneDnn(nn::Conv2dImpl& conv, const torch::Tensor& x) {
  return convOnOneDnnImpl<2>(conv, x);
}

torch::Tensor convOnOneDnn(nn::Conv3dImpl& conv, const torch::Tensor& x) {
  return convOnOneDnnImpl<3>(conv, x);
}

SemSegMapNetImpl::SemSegMapNetImpl(const NetConfig& config) : config_(config) {
  validateNetConfig(config_);
  const int w = config_.pointnet_width;
  const int n = config_.num_points;
  sa1_ = {n / config_.sa1_divisor, config_.sa1_radius, config_.sa_neighbours,
          register_module("sa1", pointwiseMlp({6, w, w, 2 * w}))};
  sa2_ = {n / config_.sa2_divisor, config_.sa2_radius, config_.sa_neighbours,
          register_module("sa2", pointwiseMlp({2 * w + 3, 2 * w, 2 * w, 4 * w}))};
  sa3_ = {0, 0.0f, 0, register_module("sa3", pointwiseMlp({4 * w + 3, 4 * w, 8 * w}))};

  class_cnn_ = register_module(
      "class_cnn", nn::ModuleList(nn::Conv3d(nn::Conv3dOptions(config_.num_classes, w, 1)),
                                  nn::Conv3d(nn::Conv3dOptions(w, 2 * w, 2)),
                                  nn::Conv3d(nn::Conv3dOptions(2 * w, 4 * w, 2))));
  scale_embedding_ = register_module("scale_embedding", nn::Linear(1, w));
  head_ = register_module("head", nn::Linear(13 * w, config_.descriptor_dim));

  decoder_seed_ = register_module("decoder_seed", nn::Linear(config_.descriptor_dim, 4 * w * 8));
  nn::Sequential decoder;
  int channels = 4 * w;
  for (int size = 2; size < config_.recon_grid; size *= 2) {
    const int next = std::max(channels / 2, 8);
    decoder->push_back(
        nn::ConvTranspose3d(nn::ConvTranspose3dOptions(channels, next, 2).stride(2)));
    decoder->push_back(nn::ReLU());
    channels = next;
  }
  decoder->push_back(nn::Conv3d(nn::Conv3dOptions(channels, 1, 3).padding(1)));
  decoder_ = register_module("decoder", decoder);
}

std::pair<torch::Tensor, torch::Tensor> SemSegMapNetImpl::abstract(SetAbstraction& level,
                                                                   const torch::Tensor& xyz,
                                                                   const torch::Tensor& features) {
  if (level.centres == 0) {
    // [B, n, 3 + c] seen as [B, 3 + c, 1, n] (channels-last strides, which oneDNN takes as is):
    // one group of all n points.
    const torch::Tensor grouped = torch::cat({xyz, features}, 2).unsqueeze(1);
    const torch::Tensor out =
        convReluStack<nn::Conv2dImpl>(level.mlp, grouped.permute({0, 3, 1, 2}));
    return {torch::Tensor(), maxOverNeighbours(out).squeeze(1)};
  }
  const auto [centres, neighbours] =
      sampleAndGroup(xyz, level.centres, level.radius, level.neighbours);
  const torch::Tensor centre_xyz = gatherRows(xyz, centres);  // [B, m, 3]
  const torch::Tensor offsets =
      (gatherRows(xyz, neighbours) - centre_xyz.unsqueeze(2)) / level.radius;  // [B, m, k, 3]
  const torch::Tensor grouped = torch::cat({offsets, gatherRows(features, neighbours)}, 3);
  const torch::Tensor out =
      convReluStack<nn::Conv2dImpl>(level.mlp, grouped.permute({0, 3, 1, 2}));  // [B, c', m, k]
  return {centre_xyz, maxOverNeighbours(out)};                                  // [B, m, c']
}

torch::Tensor SemSegMapNetImpl::encode(const NetInput& input) {
  const torch::Tensor xyz = input.points.narrow(2, 0, 3).contiguous();
  const torch::Tensor color = input.points.narrow(2, 3, 3);
  auto [xyz1, f1] = abstract(sa1_, xyz, color);
  auto [xyz2, f2] = abstract(sa2_, xyz1, f1);
  const torch::Tensor shape = abstract(sa3_, xyz2, f2).second;  // [B, 8w]
  const torch::Tensor classes =
      convReluStack<nn::Conv3dImpl>(class_cnn_, input.class_grid).flatten(1);  // [B, 4w]
  const torch::Tensor scale =
      torch::relu(scale_embedding_->forward(torch::log(input.scale.clamp_min(1e-3))));
  return head_->forward(torch::cat({shape, classes, scale}, 1));
}

NetOutput SemSegMapNetImpl::forward(const NetInput& input) {
  NetOutput out;
  out.descriptor = encode(input);
  const int64_t b = out.descriptor.size(0);
  const torch::Tensor seed =
      torch::relu(decoder_seed_->forward(out.descriptor)).view({b, -1, 2, 2, 2});
  out.reconstruction = decoder_->forward(seed);
  return out;
}

}  // namespace semsegmap
