// Model files. Layout (little-endian):
//   "SSMNET"  uint32 format version  string kind  int32 x 8 NetConfig fields  char[16] fingerprint
//   uint64 tensor count, then per parameter and buffer in the module's order:
//   string name  uint32 rank  int64 x rank sizes  float32 x numel data
// (string = uint32 length + bytes). The weights are raw tensors rather than torch::save's zip
// archive so that a file of another configuration is caught by name and shape, and a truncated
// one by its length, each with a message that says which.
#include <unistd.h>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>

#include "semsegmap/describe/learned_net.h"

namespace semsegmap {

namespace {

constexpr char kMagic[6] = {'S', 'S', 'M', 'N', 'E', 'T'};
constexpr uint32_t kFormatVersion = 1;

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "model files are little-endian");

std::vector<int32_t> configFields(const NetConfig& c) {
  return {c.descriptor_dim, c.num_points, c.num_classes,    c.grid_xy,
          c.grid_z,         c.recon_grid, c.pointnet_width, c.cnn_width};
}

NetConfig configFromFields(DescriptorKind kind, const std::vector<int32_t>& f) {
  NetConfig c;
  c.kind = kind;
  c.descriptor_dim = f[0];
  c.num_points = f[1];
  c.num_classes = f[2];
  c.grid_xy = f[3];
  c.grid_z = f[4];
  c.recon_grid = f[5];
  c.pointnet_width = f[6];
  c.cnn_width = f[7];
  return c;
}

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

class Writer {
 public:
  template <typename T>
  void pod(const T& value) {
    bytes_.append(reinterpret_cast<const char*>(&value), sizeof value);
  }
  void raw(const void* data, size_t size) { bytes_.append(static_cast<const char*>(data), size); }
  void str(const std::string& s) {
    pod(static_cast<uint32_t>(s.size()));
    bytes_ += s;
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

class Reader {
 public:
  explicit Reader(std::string bytes) : bytes_(std::move(bytes)) {}
  const char* take(size_t size) {
    if (size > bytes_.size() - pos_) throw std::runtime_error("truncated file");
    const char* p = bytes_.data() + pos_;
    pos_ += size;
    return p;
  }
  template <typename T>
  T pod() {
    T value;
    std::memcpy(&value, take(sizeof value), sizeof value);
    return value;
  }
  std::string str() {
    const uint32_t size = pod<uint32_t>();
    return std::string(take(size), size);
  }
  bool atEnd() const { return pos_ == bytes_.size(); }

 private:
  std::string bytes_;
  size_t pos_ = 0;
};

std::string shapeText(c10::IntArrayRef sizes) {
  std::ostringstream s;
  s << sizes;
  return s.str();
}

std::shared_ptr<DescriptorNetImpl> parseNet(Reader& in, std::optional<DescriptorKind> expected) {
  if (std::memcmp(in.take(sizeof kMagic), kMagic, sizeof kMagic) != 0) {
    throw std::runtime_error("not a semsegmap model file (bad magic)");
  }
  const uint32_t version = in.pod<uint32_t>();
  if (version != kFormatVersion) {
    throw std::runtime_error("model format version " + std::to_string(version) +
                             ", this build reads version " + std::to_string(kFormatVersion));
  }
  const std::string kind_name = in.str();
  DescriptorKind kind;
  try {
    kind = parseDescriptorKind(kind_name);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("corrupt header: ") + e.what());
  }
  if (expected && kind != *expected) {
    throw std::runtime_error("holds a " + kind_name + " model, expected " +
                             descriptorName(*expected));
  }
  std::vector<int32_t> fields(configFields(NetConfig{}).size());
  for (int32_t& f : fields) f = in.pod<int32_t>();
  const std::string fingerprint(in.take(16), 16);

  std::shared_ptr<DescriptorNetImpl> net;
  try {
    net = makeNet(configFromFields(kind, fields));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("corrupt header: ") + e.what());
  }
  const auto tensors = namedTensors(*net);
  const uint64_t count = in.pod<uint64_t>();
  if (count != tensors.size()) {
    throw std::runtime_error("weights do not match the configuration: " + std::to_string(count) +
                             " tensors in the file, " + std::to_string(tensors.size()) +
                             " expected");
  }
  torch::NoGradGuard no_grad;
  for (const auto& [name, tensor] : tensors) {
    const std::string file_name = in.str();
    const uint32_t rank = in.pod<uint32_t>();
    std::vector<int64_t> sizes(rank);
    for (int64_t& s : sizes) s = in.pod<int64_t>();
    if (file_name != name || c10::IntArrayRef(sizes) != tensor.sizes()) {
      throw std::runtime_error("weights do not match the configuration: " + file_name + " " +
                               shapeText(sizes) + " in the file, " + name + " " +
                               shapeText(tensor.sizes()) + " expected");
    }
    const size_t bytes = static_cast<size_t>(tensor.numel()) * sizeof(float);
    const char* data = in.take(bytes);
    torch::Tensor values = torch::empty(tensor.sizes(), torch::kFloat);
    std::memcpy(values.data_ptr<float>(), data, bytes);
    tensor.copy_(values);
  }
  if (!in.atEnd()) throw std::runtime_error("corrupt file: trailing data after the weights");
  if (netFingerprint(*net) != fingerprint) {
    throw std::runtime_error("corrupt weights: fingerprint " + netFingerprint(*net) +
                             " does not match the header's " + fingerprint);
  }
  return net;
}

}  // namespace

std::string netFingerprint(DescriptorNetImpl& net) {
  uint64_t h = 0xcbf29ce484222325ULL;  // FNV-1a 64
  const auto mix = [&h](const void* data, size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < size; ++i) {
      h ^= p[i];
      h *= 0x100000001b3ULL;
    }
  };
  const std::string kind = descriptorName(net.config().kind);
  mix(kind.data(), kind.size());
  for (const int32_t f : configFields(net.config())) mix(&f, sizeof f);
  for (const auto& [name, tensor] : namedTensors(net)) {
    mix(name.data(), name.size());
    for (const int64_t s : tensor.sizes()) mix(&s, sizeof s);
    const torch::Tensor values = cpuFloat(tensor);
    mix(values.data_ptr<float>(), static_cast<size_t>(values.numel()) * sizeof(float));
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

void saveNet(const std::filesystem::path& path, DescriptorNetImpl& net) {
  Writer out;
  out.raw(kMagic, sizeof kMagic);
  out.pod(kFormatVersion);
  out.str(descriptorName(net.config().kind));
  for (const int32_t f : configFields(net.config())) out.pod(f);
  const std::string fingerprint = netFingerprint(net);
  out.raw(fingerprint.data(), fingerprint.size());
  const auto tensors = namedTensors(net);
  out.pod(static_cast<uint64_t>(tensors.size()));
  for (const auto& [name, tensor] : tensors) {
    out.str(name);
    out.pod(static_cast<uint32_t>(tensor.dim()));
    for (const int64_t s : tensor.sizes()) out.pod(s);
    const torch::Tensor values = cpuFloat(tensor);
    out.raw(values.data_ptr<float>(), static_cast<size_t>(values.numel()) * sizeof(float));
  }

  // describe/ does not link io/, so the write-then-rename of io/atomic_file is repeated here.
  std::filesystem::path tmp = path;
  tmp += ".tmp." + std::to_string(::getpid());
  {
    std::ofstream file(tmp, std::ios::binary | std::ios::trunc);
    file.write(out.bytes().data(), static_cast<std::streamsize>(out.bytes().size()));
    file.flush();
    if (!file) {
      std::error_code ignored;
      std::filesystem::remove(tmp, ignored);
      throw std::runtime_error(path.string() + ": cannot write model file");
    }
  }
  std::error_code error;
  std::filesystem::rename(tmp, path, error);
  if (error) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error(path.string() + ": cannot write model file (" + error.message() + ")");
  }
}

std::shared_ptr<DescriptorNetImpl> loadNet(const std::filesystem::path& path,
                                           std::optional<DescriptorKind> expected) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw std::runtime_error(path.string() + ": cannot open model file (missing or not a file)");
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) throw std::runtime_error(path.string() + ": cannot open model file");
  std::ostringstream bytes;
  bytes << file.rdbuf();
  if (!file && !file.eof()) throw std::runtime_error(path.string() + ": cannot read model file");
  Reader in(bytes.str());
  try {
    return parseNet(in, expected);
  } catch (const std::exception& e) {
    throw std::runtime_error(path.string() + ": " + e.what());
  }
}

}  // namespace semsegmap
