#include "semsegmap/localize/descriptor_index.h"

#include <faiss/IndexFlat.h>
#include <faiss/IndexIVFFlat.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace semsegmap {

using FaissId = faiss::Index::idx_t;

struct DescriptorIndex::Impl {
  std::unique_ptr<faiss::IndexFlatL2> quantizer;  // IVF's list centroids; outlives the index
  std::unique_ptr<faiss::Index> index;
  faiss::IndexIVFFlat* ivf = nullptr;  // the same index when approximate
  bool approximate = false;
};

namespace {

// A Ref may point into a larger matrix (outer stride > cols); faiss needs the rows packed.
const float* packedRows(const Eigen::Ref<const DescriptorMatrix>& m, DescriptorMatrix& storage) {
  if (m.rows() <= 1 || m.outerStride() == m.cols()) return m.data();
  storage = m;
  return storage.data();
}

// k-means sample: faiss wants at least 39 points a list; more lengthen the training for little.
constexpr int kTrainingPointsPerList = 64;

// faiss's rule of thumb, 4 sqrt(n) lists, as long as each gets enough training points.
size_t listsFor(size_t n, size_t configured) {
  const size_t most = std::max<size_t>(1, n / 39);
  if (configured > 0) return std::min(configured, most);
  return std::clamp<size_t>(static_cast<size_t>(4 * std::sqrt(static_cast<double>(n))), 1, most);
}

}  // namespace

DescriptorIndex::DescriptorIndex(const DescriptorIndexConfig& config)
    : config_(config), impl_(std::make_unique<Impl>()) {
  if (config_.k <= 0) throw std::invalid_argument("DescriptorIndex: k must be positive");
  if (config_.ivf_probes <= 0 || config_.ivf_training_iterations <= 0)
    throw std::invalid_argument("DescriptorIndex: IVF probes and iterations must be positive");
}

DescriptorIndex::~DescriptorIndex() = default;
DescriptorIndex::DescriptorIndex(DescriptorIndex&&) noexcept = default;
DescriptorIndex& DescriptorIndex::operator=(DescriptorIndex&&) noexcept = default;

void DescriptorIndex::build(const Eigen::Ref<const DescriptorMatrix>& descriptors) {
  const int d = static_cast<int>(descriptors.cols());
  if (d <= 0) throw std::invalid_argument("DescriptorIndex::build: descriptors have no columns");
  const auto n = static_cast<size_t>(descriptors.rows());
  auto impl = std::make_unique<Impl>();
  impl->approximate = n > 0 && n >= config_.exact_below;
  DescriptorMatrix storage;
  const float* x = n > 0 ? packedRows(descriptors, storage) : nullptr;
  if (impl->approximate) {
    const size_t lists = listsFor(n, config_.ivf_lists);
    impl->quantizer = std::make_unique<faiss::IndexFlatL2>(d);
    auto ivf = std::make_unique<faiss::IndexIVFFlat>(impl->quantizer.get(), d, lists);
    ivf->cp.niter = config_.ivf_training_iterations;
    ivf->cp.max_points_per_centroid = kTrainingPointsPerList;
    ivf->train(static_cast<FaissId>(n), x);
    ivf->nprobe = std::min(static_cast<size_t>(config_.ivf_probes), lists);
    impl->ivf = ivf.get();
    impl->index = std::move(ivf);
  } else {
    impl->index = std::make_unique<faiss::IndexFlatL2>(d);
  }
  if (n > 0) impl->index->add(static_cast<FaissId>(n), x);
  impl_ = std::move(impl);
}

void DescriptorIndex::add(const Eigen::Ref<const DescriptorMatrix>& descriptors) {
  if (!impl_->index) throw std::logic_error("DescriptorIndex::add before build");
  if (descriptors.cols() != impl_->index->d)
    throw std::invalid_argument("DescriptorIndex::add: dimension " +
                                std::to_string(descriptors.cols()) + " but the index has " +
                                std::to_string(impl_->index->d));
  if (descriptors.rows() == 0) return;
  DescriptorMatrix storage;
  impl_->index->add(static_cast<FaissId>(descriptors.rows()), packedRows(descriptors, storage));
}

void DescriptorIndex::setProbes(int probes) {
  if (probes <= 0) throw std::invalid_argument("DescriptorIndex: probes must be positive");
  config_.ivf_probes = probes;
  if (impl_->ivf) impl_->ivf->nprobe = std::min(static_cast<size_t>(probes), impl_->ivf->nlist);
}

size_t DescriptorIndex::lists() const {
  return impl_->ivf ? impl_->ivf->nlist : 0;
}

bool DescriptorIndex::approximate() const {
  return impl_->approximate;
}

size_t DescriptorIndex::size() const {
  return impl_->index ? static_cast<size_t>(impl_->index->ntotal) : 0;
}

int DescriptorIndex::dimension() const {
  return impl_->index ? impl_->index->d : 0;
}

Neighbours DescriptorIndex::search(const Eigen::Ref<const DescriptorMatrix>& queries, int k) const {
  if (k <= 0) k = config_.k;
  if (impl_->index && queries.cols() != impl_->index->d)
    throw std::invalid_argument("DescriptorIndex::search: query dimension " +
                                std::to_string(queries.cols()) + " but the index has " +
                                std::to_string(impl_->index->d));
  const auto nq = static_cast<size_t>(queries.rows());
  Neighbours out;
  out.k = k;
  out.ids.assign(nq * k, -1);
  out.squared_distances.assign(nq * k, std::numeric_limits<float>::infinity());
  if (nq == 0 || size() == 0) return out;

  DescriptorMatrix storage;
  const float* x = packedRows(queries, storage);
  static_assert(std::is_same<FaissId, int64_t>::value, "faiss ids are int64_t");
  impl_->index->search(static_cast<FaissId>(nq), x, k, out.squared_distances.data(),
                       out.ids.data());
  // faiss pads missing neighbours with its own sentinel distance; make it the documented one.
  for (size_t i = 0; i < out.ids.size(); ++i)
    if (out.ids[i] < 0) out.squared_distances[i] = std::numeric_limits<float>::infinity();
  return out;
}

}  // namespace semsegmap
