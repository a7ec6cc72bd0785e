// A describer for wiring tests: the same random vector for every observation of one ground-truth
// instance (the simulator's), so that a test of a mode isolates the mode from descriptor quality.
#pragma once

#include <map>
#include <random>

#include "semsegmap/describe/descriptor.h"

namespace semsegmap {

class OracleDescriber : public Describer {
 public:
  DescriptorKind kind() const override { return DescriptorKind::kEigen; }
  int dimension() const override { return 8; }
  std::string fingerprint() const override { return "oracle"; }
  Eigen::MatrixXf describe(const std::vector<DescriptorInput>& batch) override {
    Eigen::MatrixXf out(static_cast<Eigen::Index>(batch.size()), 8);
    for (size_t i = 0; i < batch.size(); ++i) {
      std::map<uint16_t, size_t> votes;
      for (const EnrichedPoint& p : *batch[i].points) ++votes[p.instance_id];
      uint16_t best = 0;
      size_t most = 0;
      for (const auto& [id, n] : votes)
        if (n > most) best = id, most = n;
      std::mt19937 rng(best);
      std::normal_distribution<float> g;
      for (int k = 0; k < 8; ++k) out(static_cast<Eigen::Index>(i), k) = g(rng);
    }
    return out;
  }
};

}  // namespace semsegmap
