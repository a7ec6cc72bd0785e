// Nearest target-map descriptors for the local segments (paper section III-D, the k-NN step).
//
// Small maps are searched exactly (IndexFlatL2). Large maps use IVF (faiss IndexIVFFlat: k-means
// lists, a query scans the vectors of its nearest lists) rather than HNSW. Measured with this
// faiss build (Debian 1.7.3) on 1M unit-norm 64-d descriptors around 1000 centres, 100 queries,
// on 2 cores shared with a training job:
// - IVF, 4000 lists (the default 4 sqrt(n)), 16 probes: recall@16 1.00, 13 ms of CPU (26 ms
//   wall under that load) for the 100 queries, built in ~2 min (k-means on 256k samples);
// - HNSW, M = 32, efConstruction 40: recall@16 0.90 at efSearch 64 (57 ms wall), 0.94 at 192
//   (95 ms), built in 5-6 min: its walk pays a cache miss per visited vector, and its graph
//   links clustered data poorly unless built with a much wider (slower) beam.
// On data without clusters (a 16-d manifold) IVF with 16 probes still retrieves the map
// descriptor a noisy copy came from every time, but its recall@16 of the exact neighbours is
// 0.73 (0.96 at 64 probes, ~85 ms); HNSW does better there (0.95 at efSearch 32, 200k points),
// so with such descriptors raise the probes or revisit the choice. IVF's search is
// deterministic, its k-means seeded, and more probes trade speed for recall without a rebuild.
// faiss headers stay out of this header (pimpl), so users do not compile them.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace semsegmap {

// faiss reads descriptors as contiguous row-major floats: one descriptor a row.
using DescriptorMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

struct DescriptorIndexConfig {
  int k = 16;                  // neighbours per query (the paper's k)
  size_t exact_below = 20000;  // maps with fewer descriptors are searched exactly (IndexFlatL2)
  // IVF: inverted lists (0: 4 sqrt(n), faiss's rule of thumb, at most n / 39 so that k-means
  // has enough points a list) and lists scanned per query.
  size_t ivf_lists = 0;
  int ivf_probes = 16;
  int ivf_training_iterations = 10;  // k-means; lists need not be optimal, only coherent
};

// Row-major [queries x k]; id -1 and +inf distance where fewer than k neighbours exist.
struct Neighbours {
  int k = 0;
  std::vector<int64_t> ids;
  std::vector<float> squared_distances;

  size_t queries() const { return k > 0 ? ids.size() / static_cast<size_t>(k) : 0; }
  int64_t id(size_t query, int j) const { return ids[query * k + j]; }
  float squaredDistance(size_t query, int j) const { return squared_distances[query * k + j]; }
  const int64_t* idsOf(size_t query) const { return ids.data() + query * k; }
  const float* squaredDistancesOf(size_t query) const {
    return squared_distances.data() + query * k;
  }
};

class DescriptorIndex {
 public:
  explicit DescriptorIndex(const DescriptorIndexConfig& config = {});
  ~DescriptorIndex();
  DescriptorIndex(DescriptorIndex&&) noexcept;
  DescriptorIndex& operator=(DescriptorIndex&&) noexcept;
  DescriptorIndex(const DescriptorIndex&) = delete;
  DescriptorIndex& operator=(const DescriptorIndex&) = delete;

  // Replaces the contents; row i gets id i. A row-major matrix is used in place, anything else
  // (e.g. a column-major MatrixXf) is converted by Eigen into a row-major temporary.
  void build(const Eigen::Ref<const DescriptorMatrix>& descriptors);

  // Appends rows with the next ids (the index must have been built, with the same dimension).
  void add(const Eigen::Ref<const DescriptorMatrix>& descriptors);

  bool approximate() const;
  size_t size() const;
  int dimension() const;  // 0 before build()
  const DescriptorIndexConfig& config() const { return config_; }
  // IVF lists scanned per query: recall against speed, without rebuilding. Not while searching.
  void setProbes(int probes);
  size_t lists() const;  // IVF lists; 0 when exact

  // Nearest descriptors of every query row, nearest first. k <= 0: config().k. Throws
  // std::invalid_argument when the query dimension differs from the built one; an index that
  // is empty (or was never built) returns id -1 everywhere.
  Neighbours search(const Eigen::Ref<const DescriptorMatrix>& queries, int k = 0) const;

 private:
  struct Impl;
  DescriptorIndexConfig config_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace semsegmap
