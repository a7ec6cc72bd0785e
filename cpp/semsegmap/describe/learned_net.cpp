// Inputs, construction and loss of the learned descriptors; the networks themselves are in
// semsegmap_net.cpp and segmap_cnn.cpp, the model files in model_file.cpp.
#include "semsegmap/describe/learned_net.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "semsegmap/describe/net_input.h"
#include "semsegmap/describe/segmap_cnn.h"
#include "semsegmap/describe/semsegmap_net.h"
#include "semsegmap/describe/smoothnet.h"
#include "semsegmap/describe/smoothnet_input.h"

namespace semsegmap {

namespace {

void copyInto(torch::Tensor& batch, int64_t row, const std::vector<float>& values) {
  std::copy(values.begin(), values.end(), batch.data_ptr<float>() + row * int64_t(values.size()));
}

}  // namespace

NetInput makeNetInput(const NetConfig& config, const std::vector<const EnrichedCloud*>& segments,
                      std::mt19937& rng) {
  std::vector<uint64_t> salts(segments.size());
  for (uint64_t& salt : salts) salt = static_cast<uint64_t>(rng()) << 32 | rng();
  return makeNetInput(config, segments, salts);
}

NetInput makeNetInput(const NetConfig& config, const std::vector<const EnrichedCloud*>& segments,
                      const std::vector<uint64_t>& salts) {
  validateNetConfig(config);
  if (salts.size() != segments.size()) {
    throw std::invalid_argument("makeNetInput: " + std::to_string(segments.size()) +
                                " segments but " + std::to_string(salts.size()) + " salts");
  }
  const int64_t b = static_cast<int64_t>(segments.size());
  NetInput in;
  in.n_points = torch::empty({b});
  for (int64_t i = 0; i < b; ++i) {
    if (segments[i] == nullptr || segments[i]->empty()) {
      throw std::invalid_argument("makeNetInput: segment " + std::to_string(i) +
                                  " of the batch has no points");
    }
    in.n_points.data_ptr<float>()[i] = static_cast<float>(segments[i]->size());
  }
  if (config.kind == DescriptorKind::kSemSegMapNet) {
    const int64_t r = config.recon_grid;
    in.points = torch::empty({b, config.num_points, 6});
    in.class_grid = torch::empty({b, config.num_classes, 3, 3, 3});
    in.scale = torch::empty({b, 1});
    in.target_occupancy = torch::empty({b, 1, r, r, r});
    at::parallel_for(0, b, 1, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i) {
        const PointNetSample s =
            makePointNetSample(*segments[i], config.num_points, config.num_classes,
                               config.recon_grid, salts[i], config.use_color, config.use_classes);
        copyInto(in.points, i, s.points);
        copyInto(in.class_grid, i, s.class_grid);
        in.scale.data_ptr<float>()[i] = s.scale;
        copyInto(in.target_occupancy, i, s.occupancy);
      }
    });
  } else if (config.kind == DescriptorKind::kSmoothNetBow) {
    const int64_t k = config.smoothnet_keypoints, g = config.smoothnet_voxels;
    in.sdv = torch::empty({b * k, 1, g, g, g});
    in.keypoints = k;
    at::parallel_for(0, b, 1, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i)
        copyInto(in.sdv, i,
                 smoothNetSample(*segments[i], config.smoothnet_keypoints, config.smoothnet_radius,
                                 config.smoothnet_voxels, salts[i]));
    });
  } else {
    in.occupancy = torch::empty({b, 1, config.grid_xy, config.grid_xy, config.grid_z});
    in.scale = torch::empty({b, 3});
    at::parallel_for(0, b, 1, [&](int64_t begin, int64_t end) {
      for (int64_t i = begin; i < end; ++i) {
        const OccupancyGridSample s = makeSegMapGrid(*segments[i], config.grid_xy, config.grid_z);
        copyInto(in.occupancy, i, s.occupancy);
        std::copy(s.extent_m.begin(), s.extent_m.end(), in.scale.data_ptr<float>() + 3 * i);
      }
    });
    in.target_occupancy = in.occupancy;
  }
  return in;
}

std::shared_ptr<DescriptorNetImpl> makeNet(const NetConfig& config) {
  validateNetConfig(config);
  if (config.kind == DescriptorKind::kSemSegMapNet) {
    return std::make_shared<SemSegMapNetImpl>(config);
  }
  if (config.kind == DescriptorKind::kSmoothNetBow) return std::make_shared<SmoothNetImpl>(config);
  return std::make_shared<SegMapCnnImpl>(config);
}

torch::Tensor tripletLoss(const torch::Tensor& anchor, const torch::Tensor& positive,
                          const torch::Tensor& negative, const torch::Tensor& sigma,
                          double margin) {
  if (anchor.dim() != 2 || positive.sizes() != anchor.sizes() ||
      negative.sizes() != anchor.sizes() || sigma.numel() != anchor.size(0)) {
    throw std::invalid_argument(
        "tripletLoss: expected anchor, positive, negative [B, D] and "
        "sigma [B] of one batch size");
  }
  // The floor keeps the gradient of sqrt finite when two descriptors coincide (e.g. an anchor
  // and its positive made from the same points); it changes no distance above 1e-6.
  const auto distance = [](const torch::Tensor& a, const torch::Tensor& b) {
    return torch::sqrt((a - b).pow(2).sum(1).clamp_min(1e-12));
  };
  return torch::relu(margin + sigma.reshape({-1}) * distance(anchor, positive) -
                     distance(anchor, negative))
      .mean();
}

}  // namespace semsegmap
