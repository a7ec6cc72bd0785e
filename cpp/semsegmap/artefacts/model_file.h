// Model files of the learned descriptors. Layout (little-endian, core/binary_io.h):
//   "SSMNET"  uint32 format version  string kind  int32 x 8 NetConfig fields
//   [version 2: int32 sa1_divisor, sa2_divisor, sa_neighbours, float32 sa1_radius, sa2_radius]
//   [version 3: uint8 use_color, use_classes]
//   [version 4: int32 smoothnet_keypoints, smoothnet_voxels, smoothnet_local_dim,
//    smoothnet_width, float32 smoothnet_radius (3dsmoothnet, written for every kind)]
//   char[16] fingerprint  uint64 tensor count, then per parameter and buffer in the module's
//   order: string name  uint32 rank  int64 x rank sizes  float32 x numel data
// (string = uint32 length + bytes). The weights are raw tensors rather than torch::save's zip
// archive so that a file of another configuration is caught by name and shape, and a truncated
// one by its length, each with a message that says which. Version 1 files are read with the set
// abstraction values every one of them was trained with (NetConfig's defaults).
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "semsegmap/describe/descriptor.h"
#include "semsegmap/describe/net_config.h"
#include "semsegmap/pipeline/pipeline_config.h"

namespace semsegmap {

class DescriptorNetImpl;

constexpr uint32_t kModelFormatVersion = 4;

// Written to a temporary name and renamed. Throws std::runtime_error naming the file.
void writeModelFile(const std::filesystem::path& path, const Model& model);
// Throws std::runtime_error "<path>: <what is wrong>" when the file is missing, truncated,
// corrupt, of an unknown version or holds another kind than `expected` (when given). Every
// length is checked against the file's size before anything is allocated.
Model readModelFile(const std::filesystem::path& path,
                    std::optional<DescriptorKind> expected = std::nullopt);

#if SEMSEGMAP_WITH_TORCH
// The network of a model file, and back (only in a build with libtorch).
void saveNet(const std::filesystem::path& path, DescriptorNetImpl& net);
std::shared_ptr<DescriptorNetImpl> loadNet(const std::filesystem::path& path,
                                           std::optional<DescriptorKind> expected = std::nullopt);
#endif

// The describer a configuration asks for (descriptor.kind, and descriptor.model for the learned
// kinds); `threads` 0: all cores. Checks requireDescriberBuilt first.
std::unique_ptr<Describer> makeDescriber(const DescriptorConfig& config, int threads = 0);

// Throws std::runtime_error "[where: ]descriptor.kind K: this build has no ... (built without
// ..., reconfigure with -D...=ON)" when this build lacks the describer of `config`
// (descriptorNotBuilt), without loading anything: for commands to fail before they start.
void requireDescriberBuilt(const DescriptorConfig& config, const std::string& where = "");

}  // namespace semsegmap
