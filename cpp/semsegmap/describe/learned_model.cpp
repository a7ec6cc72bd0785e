// A network and its plain Model value (describe/net_config.h), both ways, and its fingerprint.
// The bytes of a model file are artefacts/model_file.cpp's business.
#include <cstdio>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string>

#include "semsegmap/core/binary_io.h"
#include "semsegmap/describe/learned_net.h"

namespace semsegmap {

namespace {

// Every parameter and buffer, in the module's (registration) order.
std::vector<std::pair<std::string, torch::Tensor>> namedTensors(DescriptorNetImpl& net) {
  std::vector<std::pair<std::string, torch::Tensor>> out;
  for (const auto& item : net.named_parameters(true)) out.emplace_back(item.key(), item.value());
  for (const auto& item : net.named_buffers(true)) out.emplace_back(item.key(), item.value());
  return out;
}

torch::Tensor cpuFloat(const torch::Tensor& t) {
  return t.detach().to(torch::kCPU, torch::kFloat).contiguous();
}

std::string shapeText(c10::IntArrayRef sizes) {
  std::ostringstream s;
  s << sizes;
  return s.str();
}

// The configuration as hashed. The set abstraction fields came after the first shipped models:
// they enter the hash only when they differ from the values those models were trained with, so
// that the fingerprints of existing models (and of the maps built with them) stay valid while an
// edited value still gives another fingerprint.
uint64_t mixConfig(const NetConfig& c, uint64_t h) {
  const std::string kind = descriptorName(c.kind);
  h = fnv1a64(kind.data(), kind.size(), h);
  const int32_t v1[] = {c.descriptor_dim, c.num_points, c.num_classes,    c.grid_xy,
                        c.grid_z,         c.recon_grid, c.pointnet_width, c.cnn_width};
  h = fnv1a64(v1, sizeof v1, h);
  const NetConfig d;
  if (c.sa1_divisor != d.sa1_divisor || c.sa1_radius != d.sa1_radius ||
      c.sa2_divisor != d.sa2_divisor || c.sa2_radius != d.sa2_radius ||
      c.sa_neighbours != d.sa_neighbours) {
    const int32_t sa[] = {c.sa1_divisor, c.sa2_divisor, c.sa_neighbours};
    const float radii[] = {c.sa1_radius, c.sa2_radius};
    h = fnv1a64(sa, sizeof sa, h);
    h = fnv1a64(radii, sizeof radii, h);
  }
  if (!c.use_color || !c.use_classes) {  // likewise: the shipped models used both
    const uint8_t flags[] = {c.use_color, c.use_classes};
    h = fnv1a64(flags, sizeof flags, h);
  }
  if (c.kind == DescriptorKind::kSmoothNetBow) {
    const int32_t v[] = {c.smoothnet_keypoints, c.smoothnet_voxels, c.smoothnet_local_dim,
                         c.smoothnet_width};
    h = fnv1a64(v, sizeof v, h);
    h = fnv1a64(&c.smoothnet_radius, sizeof c.smoothnet_radius, h);
  }
  return h;
}

}  // namespace

std::string netFingerprint(DescriptorNetImpl& net) {
  uint64_t h = mixConfig(net.config(), 0xcbf29ce484222325ULL);
  for (const auto& [name, tensor] : namedTensors(net)) {
    h = fnv1a64(name.data(), name.size(), h);
    for (const int64_t s : tensor.sizes()) h = fnv1a64(&s, sizeof s, h);
    const torch::Tensor values = cpuFloat(tensor);
    h = fnv1a64(values.data_ptr<float>(), static_cast<size_t>(values.numel()) * sizeof(float), h);
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

Model modelOf(DescriptorNetImpl& net) {
  Model model;
  model.config = net.config();
  model.fingerprint = netFingerprint(net);
  for (const auto& [name, tensor] : namedTensors(net)) {
    const torch::Tensor values = cpuFloat(tensor);
    ModelTensor t;
    t.name = name;
    t.shape.assign(tensor.sizes().begin(), tensor.sizes().end());
    t.values.assign(values.data_ptr<float>(), values.data_ptr<float>() + values.numel());
    model.tensors.push_back(std::move(t));
  }
  return model;
}

std::shared_ptr<DescriptorNetImpl> netFromModel(const Model& model) {
  std::shared_ptr<DescriptorNetImpl> net;
  try {
    net = makeNet(model.config);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("corrupt header: ") + e.what());
  }
  const auto tensors = namedTensors(*net);
  if (model.tensors.size() != tensors.size())
    throw std::runtime_error(
        "weights do not match the configuration: " + std::to_string(model.tensors.size()) +
        " tensors in the file, " + std::to_string(tensors.size()) + " expected");
  torch::NoGradGuard no_grad;
  for (size_t i = 0; i < tensors.size(); ++i) {
    const auto& [name, tensor] = tensors[i];
    const ModelTensor& t = model.tensors[i];
    if (t.name != name || c10::IntArrayRef(t.shape) != tensor.sizes() ||
        t.values.size() != static_cast<size_t>(tensor.numel()))
      throw std::runtime_error("weights do not match the configuration: " + t.name + " " +
                               shapeText(t.shape) + " in the file, " + name + " " +
                               shapeText(tensor.sizes()) + " expected");
    torch::Tensor values = torch::empty(tensor.sizes(), torch::kFloat);
    std::memcpy(values.data_ptr<float>(), t.values.data(), t.values.size() * sizeof(float));
    tensor.copy_(values);
  }
  if (netFingerprint(*net) != model.fingerprint)
    throw std::runtime_error("corrupt weights: fingerprint " + netFingerprint(*net) +
                             " does not match the header's " + model.fingerprint);
  return net;
}

}  // namespace semsegmap
