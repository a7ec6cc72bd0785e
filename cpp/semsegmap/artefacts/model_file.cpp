#include "semsegmap/artefacts/model_file.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/binary_io.h"
#if SEMSEGMAP_WITH_TORCH
#include "semsegmap/describe/learned_describer.h"
#include "semsegmap/describe/learned_net.h"
#endif

namespace semsegmap {

namespace {

constexpr std::string_view kModelMagic("SSMNET", 6);

void putConfig(BinaryWriter& w, const NetConfig& c) {
  for (const int32_t f : {c.descriptor_dim, c.num_points, c.num_classes, c.grid_xy, c.grid_z,
                          c.recon_grid, c.pointnet_width, c.cnn_width})
    w.put(f);
  for (const int32_t f : {c.sa1_divisor, c.sa2_divisor, c.sa_neighbours}) w.put(f);
  w.put(c.sa1_radius);
  w.put(c.sa2_radius);
  w.put(static_cast<uint8_t>(c.use_color));
  w.put(static_cast<uint8_t>(c.use_classes));
  for (const int32_t f :
       {c.smoothnet_keypoints, c.smoothnet_voxels, c.smoothnet_local_dim, c.smoothnet_width})
    w.put(f);
  w.put(c.smoothnet_radius);
}

bool getFlag(BinaryReader& r) {
  const uint8_t v = r.get<uint8_t>("the configuration");
  if (v > 1) r.fail("corrupt header: a modality flag of " + std::to_string(v));
  return v == 1;
}

NetConfig getConfig(BinaryReader& r, DescriptorKind kind, uint32_t version) {
  NetConfig c;  // version 1: the set abstraction defaults, which every version 1 model used
  c.kind = kind;
  for (int* f : {&c.descriptor_dim, &c.num_points, &c.num_classes, &c.grid_xy, &c.grid_z,
                 &c.recon_grid, &c.pointnet_width, &c.cnn_width})
    *f = r.get<int32_t>("the configuration");
  if (version >= 2) {
    for (int* f : {&c.sa1_divisor, &c.sa2_divisor, &c.sa_neighbours})
      *f = r.get<int32_t>("the configuration");
    c.sa1_radius = r.get<float>("the configuration");
    c.sa2_radius = r.get<float>("the configuration");
  }
  if (version >= 3) {
    c.use_color = getFlag(r);
    c.use_classes = getFlag(r);
  }
  if (version >= 4) {
    for (int* f :
         {&c.smoothnet_keypoints, &c.smoothnet_voxels, &c.smoothnet_local_dim, &c.smoothnet_width})
      *f = r.get<int32_t>("the configuration");
    c.smoothnet_radius = r.get<float>("the configuration");
  } else if (kind == DescriptorKind::kSmoothNetBow) {
    r.fail("corrupt header: a 3dsmoothnet model of format version " + std::to_string(version) +
           " (3dsmoothnet came with version 4)");
  }
  try {
    validateNetConfig(c);
  } catch (const std::invalid_argument& e) {
    r.fail(std::string("corrupt header: ") + e.what());
  }
  return c;
}

DescriptorKind getKind(BinaryReader& r, std::optional<DescriptorKind> expected) {
  const std::string name = r.getString32("the header");
  DescriptorKind kind;
  try {
    kind = parseDescriptorKind(name);
  } catch (const std::invalid_argument& e) {
    r.fail(std::string("corrupt header: ") + e.what());
  }
  if (expected && kind != *expected)
    r.fail("holds a " + name + " model, expected " + descriptorName(*expected));
  return kind;
}

std::string shapeText(const std::vector<int64_t>& shape) {
  std::string text = "[";
  for (size_t i = 0; i < shape.size(); ++i) text += (i ? ", " : "") + std::to_string(shape[i]);
  return text + "]";
}

// The next tensor, which must be the one the configuration implies: its name and shape are
// compared before its values are read (so a corrupt header can neither allocate nor build more
// than the file holds), and every value must be finite.
ModelTensor getTensor(BinaryReader& r, const TensorShape& expected) {
  ModelTensor t;
  t.name = r.getString32("a tensor name");
  const uint32_t rank = r.get<uint32_t>("a tensor shape");
  if (rank > 8) r.fail("corrupt model file: tensor " + t.name + " of rank " + std::to_string(rank));
  t.shape = r.getArray<int64_t>(rank, "a tensor shape");
  if (t.name != expected.name || t.shape != expected.shape)
    r.fail("weights do not match the configuration: " + t.name + " " + shapeText(t.shape) +
           " in the file, " + expected.name + " " + shapeText(expected.shape) + " expected");
  t.values = r.getArray<float>(expected.numel(), "the weights");
  for (const float v : t.values)
    if (!std::isfinite(v))
      r.fail("corrupt weights: tensor " + t.name + " holds " + std::to_string(v));
  return t;
}

}  // namespace

void writeModelFile(const std::filesystem::path& path, const Model& model) {
  BinaryWriter w;
  w.putBytes(kModelMagic.data(), kModelMagic.size());
  w.put(kModelFormatVersion);
  w.putString32(descriptorName(model.config.kind));
  putConfig(w, model.config);
  if (model.fingerprint.size() != 16)
    throw std::invalid_argument(path.string() + ": a model fingerprint has 16 hex digits");
  w.putBytes(model.fingerprint.data(), model.fingerprint.size());
  w.put(static_cast<uint64_t>(model.tensors.size()));
  for (const ModelTensor& t : model.tensors) {
    w.putString32(t.name);
    w.put(static_cast<uint32_t>(t.shape.size()));
    w.putArray(t.shape);
    w.putArray(t.values);
  }
  writeBytesAtomically(path, w.bytes());
}

Model readModelFile(const std::filesystem::path& path, std::optional<DescriptorKind> expected) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    throw std::runtime_error(path.string() + ": cannot open model file (missing or not a file)");
  const std::string bytes = readFileBytes(path);
  BinaryReader r(path, bytes, "model file");
  r.expectMagic(kModelMagic);
  const uint32_t version = r.get<uint32_t>("the header");
  if (version < 1 || version > kModelFormatVersion)
    r.fail("model format version " + std::to_string(version) + ", this build reads versions 1.." +
           std::to_string(kModelFormatVersion));
  Model model;
  const DescriptorKind kind = getKind(r, expected);
  model.config = getConfig(r, kind, version);
  model.fingerprint = std::string(r.take(16, "the fingerprint"), 16);
  // A tensor takes at least its name's length, its rank and one float.
  const uint64_t count = r.getCount(12, "the tensor count");
  const std::vector<TensorShape> shapes = netTensorShapes(model.config);
  if (count != shapes.size())
    r.fail("weights do not match the configuration: " + std::to_string(count) +
           " tensors in the file, " + std::to_string(shapes.size()) + " expected");
  for (const TensorShape& shape : shapes) model.tensors.push_back(getTensor(r, shape));
  r.expectEnd("the weights");
  return model;
}

#if SEMSEGMAP_WITH_TORCH
void saveNet(const std::filesystem::path& path, DescriptorNetImpl& net) {
  writeModelFile(path, modelOf(net));
}

std::shared_ptr<DescriptorNetImpl> loadNet(const std::filesystem::path& path,
                                           std::optional<DescriptorKind> expected) {
  const KeepOpenMpThreads keep;  // often the calling thread's first use of torch
  const Model model = readModelFile(path, expected);
  try {
    return netFromModel(model);
  } catch (const std::exception& e) {
    throw std::runtime_error(path.string() + ": " + e.what());
  }
}
#endif

void requireDescriberBuilt(const DescriptorConfig& config, const std::string& where) {
  const std::string missing = descriptorNotBuilt(parseDescriptorKind(config.kind));
  if (!missing.empty())
    throw std::runtime_error((where.empty() ? "" : where + ": ") + "descriptor.kind " +
                             config.kind + ": " + missing);
}

std::unique_ptr<Describer> makeDescriber(const DescriptorConfig& config, int threads) {
  requireDescriberBuilt(config);
  const DescriptorKind kind = parseDescriptorKind(config.kind);
  DescriberOptions options;
  options.threads = threads;
  options.smoothnet_keypoints = config.keypoints;
#if SEMSEGMAP_WITH_TORCH
  // Loading the network is the calling thread's first use of torch (learned_describer.h).
  const KeepOpenMpThreads keep;
  if (isLearnedDescriptor(kind)) {
    if (config.model.empty())
      throw std::invalid_argument("descriptor.kind " + config.kind +
                                  " needs a model file (descriptor.model)");
    options.net = loadNet(config.model, kind);
  }
#endif
  return makeDescriber(kind, options);
}

}  // namespace semsegmap
