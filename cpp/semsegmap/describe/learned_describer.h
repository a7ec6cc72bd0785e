// Inference with a trained segmap-cnn or semsegmap-net model file behind the Describer
// interface: what the pipeline's describe stage calls for the learned kinds.
#pragma once

#include <memory>

#include "semsegmap/describe/descriptor.h"

namespace semsegmap {

// Describes with options.net (std::invalid_argument for a hand-made kind or a missing network or
// one of another kind); the describer puts the network into eval mode. The describer
// splits a batch into chunks of at most kLearnedChunk segments for options.threads threads of
// its own (0: all cores), each running torch single-threaded (eval mode, no autograd), and
// subsamples every segment with the same fixed salt: a segment always gets the same
// descriptor, whatever its batch or the order of its points.
std::unique_ptr<Describer> makeLearnedDescriber(DescriptorKind kind,
                                                const DescriberOptions& options);

constexpr int kLearnedChunk = 64;

// glibc's malloc: allocations up to 32 MB come from the heap, and up to 512 MB of freed heap stay
// with the process. Every batch allocates and frees tens of MB of activations; with glibc's
// defaults they go back to the system and fault back in page by page, which measured 40-50 % of
// the inference time. Process-wide, so the library never calls it behind its caller's back: a
// program that describes or trains calls it once (the command line and the benchmarks do).
// Idempotent, a no-op elsewhere than glibc.
void keepFreedMemoryForTorch();

// A thread's first use of torch sets that thread's OpenMP thread count (to one, with Debian's
// libtorch on the 2-core machine), and every later OpenMP loop of the thread then runs on one
// core: the enrichment after a describer was loaded took 12-14 ms a frame instead of 7
// (BM_PipelineFrontEnd with and without a describer). The guard puts the count back when it
// goes out of scope; makeDescriber holds one while it loads a network.
class KeepOpenMpThreads {
 public:
  KeepOpenMpThreads();
  ~KeepOpenMpThreads();
  KeepOpenMpThreads(const KeepOpenMpThreads&) = delete;
  KeepOpenMpThreads& operator=(const KeepOpenMpThreads&) = delete;

 private:
  int threads_;
};

}  // namespace semsegmap
