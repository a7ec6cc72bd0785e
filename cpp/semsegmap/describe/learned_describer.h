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

}  // namespace semsegmap
