// What every descriptor training holds while it runs (trainer.cpp, smoothnet_trainer.cpp): the
// process's libtorch thread count for the duration, and the weights of the best epoch so far.
#pragma once

#include <vector>

#include <torch/torch.h>

#include "semsegmap/describe/learned_net.h"

namespace semsegmap {

// libtorch's thread count is the process's: set for a training and given back when it ends,
// however it ends.
class TorchThreadCount {
 public:
  explicit TorchThreadCount(int threads) : saved_(torch::get_num_threads()) {
    torch::set_num_threads(threads);
  }
  ~TorchThreadCount() { torch::set_num_threads(saved_); }
  TorchThreadCount(const TorchThreadCount&) = delete;
  TorchThreadCount& operator=(const TorchThreadCount&) = delete;

 private:
  int saved_;
};

// Copies of a network's parameters and buffers (the best epoch's), so that the result does not
// depend on a file.
struct WeightSnapshot {
  std::vector<torch::Tensor> tensors;
  void take(DescriptorNetImpl& net) {
    tensors.clear();
    for (const auto& t : net.parameters()) tensors.push_back(t.detach().clone());
    for (const auto& t : net.buffers()) tensors.push_back(t.detach().clone());
  }
  void restore(DescriptorNetImpl& net) const {
    if (tensors.empty()) return;
    torch::NoGradGuard no_grad;
    size_t k = 0;
    for (auto& t : net.parameters()) t.copy_(tensors[k++]);
    for (auto& t : net.buffers()) t.copy_(tensors[k++]);
  }
};

}  // namespace semsegmap
