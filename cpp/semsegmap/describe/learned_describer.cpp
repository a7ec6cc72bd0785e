// Parallel over segments with the describer's own threads, each running torch single-threaded:
// torch's intra-op parallelism (OpenMP) puts ~40 barriers into every batch, and with libgomp's
// default spin-waiting they cost 3 to 6 times the work itself as soon as other processes share
// the cores (measured on the 2-core development machine under a colleague's build).
#include "semsegmap/describe/learned_describer.h"

#include <omp.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <algorithm>
#include <atomic>
#include <exception>
#include <stdexcept>
#include <string>
#include <thread>

#include "semsegmap/describe/learned_net.h"

namespace semsegmap {

namespace {

// Any constant works; it is part of what a model's descriptors are, like the weights.
constexpr uint64_t kInferenceSalt = 0x5e35e63a9d1c0b7fULL;
// Smaller chunks than this lose more to per-operation overhead than they gain in balance.
constexpr size_t kMinChunk = 16;
// Chunks a batch is cut into (before the limits above): four per thread on this project's
// 2-core reference machine, where the shipped results were measured.
constexpr size_t kChunksPerBatch = 8;

// torch (and oneDNN) single-threaded in the calling thread for the guard's lifetime; the
// caller's OpenMP thread count is restored, so its own parallel loops are untouched. The count
// is read before torch's first use in the thread, which sets it (to one): a thread that first
// describes here (the live session's worker) kept one core for its enrichment otherwise.
class SingleThreadedTorch {
 public:
  SingleThreadedTorch() : saved_(omp_get_max_threads()) {
    at::get_num_threads();  // torch's per-thread set-up, inside the guard
    omp_set_num_threads(1);
  }
  ~SingleThreadedTorch() { omp_set_num_threads(saved_); }
  SingleThreadedTorch(const SingleThreadedTorch&) = delete;
  SingleThreadedTorch& operator=(const SingleThreadedTorch&) = delete;

 private:
  int saved_ = 1;
};

class LearnedDescriber : public Describer {
 public:
  LearnedDescriber(DescriptorKind kind, const DescriberOptions& options)
      : kind_(kind),
        threads_(options.threads > 0
                     ? options.threads
                     : std::max(1, static_cast<int>(std::thread::hardware_concurrency()))) {
    if (!isLearnedDescriptor(kind)) {
      throw std::invalid_argument("makeLearnedDescriber: " + descriptorName(kind) +
                                  " is not a learned descriptor");
    }
    if (!options.net || options.net->config().kind != kind) {
      throw std::invalid_argument("makeLearnedDescriber: " + descriptorName(kind) +
                                  " needs a network of its kind (DescriberOptions::net, loadNet)");
    }
    net_ = options.net;
    net_->eval();
    fingerprint_ = netFingerprint(*net_);
    config_ = net_->config();
    if (options.smoothnet_keypoints > 0 &&
        options.smoothnet_keypoints != config_.smoothnet_keypoints) {
      if (kind != DescriptorKind::kSmoothNetBow)
        throw std::invalid_argument("makeLearnedDescriber: keypoints are 3dsmoothnet's, not " +
                                    descriptorName(kind) + "'s");
      // Other keypoints, other descriptors: a map built with them is another map.
      config_.smoothnet_keypoints = options.smoothnet_keypoints;
      fingerprint_ += "/keypoints=" + std::to_string(config_.smoothnet_keypoints);
    }
  }

  DescriptorKind kind() const override { return kind_; }
  int dimension() const override { return net_->config().descriptor_dim; }
  std::string fingerprint() const override { return fingerprint_; }

  Eigen::MatrixXf describe(const std::vector<DescriptorInput>& batch) override {
    for (const DescriptorInput& in : batch) {
      if (in.points == nullptr) throw std::invalid_argument("describe: input without points");
    }
    const size_t n = batch.size();
    Eigen::MatrixXf out(static_cast<Eigen::Index>(n), dimension());
    // Threads take chunks from a shared counter, several each, so that a thread slowed down by
    // another process on its core does not hold up the whole batch. The chunks depend on the
    // batch alone, never on the thread count: a segment's descriptor changes in its last bits
    // with the other segments of its chunk (the network's matrix products are blocked by batch
    // size), and a run must give the same files on a machine with more cores.
    const size_t chunk =
        std::clamp(n / kChunksPerBatch, kMinChunk, static_cast<size_t>(kLearnedChunk));
    const size_t chunks = (n + chunk - 1) / chunk;
    const size_t threads = std::min(static_cast<size_t>(threads_), chunks);
    std::atomic<size_t> next{0};
    const auto work = [&] {
      const SingleThreadedTorch single_threaded;
      const torch::NoGradGuard no_grad;
      for (size_t c = next++; c < chunks; c = next++) {
        describeChunk(batch, c * chunk, std::min(n, (c + 1) * chunk), out);
      }
    };
    if (threads <= 1) {
      work();
      return out;
    }
    std::vector<std::thread> pool;
    std::vector<std::exception_ptr> errors(threads);
    for (size_t t = 0; t < threads; ++t) {
      pool.emplace_back([&, t] {
        try {
          work();
        } catch (...) {
          errors[t] = std::current_exception();
          next = chunks;  // the others stop after their current chunk
        }
      });
    }
    for (std::thread& thread : pool) thread.join();
    for (const std::exception_ptr& error : errors) {
      if (error) std::rethrow_exception(error);
    }
    return out;
  }

 private:
  // Rows [begin, end) of `out`; chunks write disjoint rows, so no locking.
  void describeChunk(const std::vector<DescriptorInput>& batch, size_t begin, size_t end,
                     Eigen::MatrixXf& out) {
    const size_t count = end - begin;
    std::vector<const EnrichedCloud*> segments(count);
    for (size_t i = 0; i < count; ++i) segments[i] = batch[begin + i].points;
    const NetInput input =
        makeNetInput(config_, segments, std::vector<uint64_t>(count, kInferenceSalt));
    const torch::Tensor descriptors = net_->encode(input).contiguous();
    const float* d = descriptors.data_ptr<float>();
    const int dim = dimension();
    for (size_t i = 0; i < count; ++i) {
      for (int j = 0; j < dim; ++j) {
        out(static_cast<Eigen::Index>(begin + i), j) = d[i * static_cast<size_t>(dim) + j];
      }
    }
  }

  DescriptorKind kind_;
  int threads_;
  std::shared_ptr<DescriptorNetImpl> net_;
  NetConfig config_;  // the network's, with the describer's keypoints
  std::string fingerprint_;
};

}  // namespace

KeepOpenMpThreads::KeepOpenMpThreads() : threads_(omp_get_max_threads()) {}
KeepOpenMpThreads::~KeepOpenMpThreads() {
  omp_set_num_threads(threads_);
}

void keepFreedMemoryForTorch() {
#ifdef __GLIBC__
  static const bool once = [] {
    // Setting either also turns off glibc's own adjustment of both, hence both.
    return mallopt(M_MMAP_THRESHOLD, 32 << 20) == 1 && mallopt(M_TRIM_THRESHOLD, 512 << 20) == 1;
  }();
  (void)once;
#endif
}

std::unique_ptr<Describer> makeLearnedDescriber(DescriptorKind kind,
                                                const DescriberOptions& options) {
  return std::make_unique<LearnedDescriber>(kind, options);
}

}  // namespace semsegmap
