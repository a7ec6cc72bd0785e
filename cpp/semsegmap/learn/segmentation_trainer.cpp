#include "semsegmap/learn/segmentation_trainer.h"

#include <torch/torch.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>

#include "semsegmap/learn/onnx_writer.h"

namespace semsegmap {

namespace {

// 3x3 convolution, batch norm, ReLU; the norm is folded into the convolution on export.
struct ConvBnImpl : torch::nn::Module {
  ConvBnImpl(int in, int out, int stride, int dilation)
      : conv(register_module("conv", torch::nn::Conv2d(torch::nn::Conv2dOptions(in, out, 3)
                                                           .stride(stride)
                                                           .padding(dilation)
                                                           .dilation(dilation)
                                                           .bias(false)))),
        bn(register_module("bn", torch::nn::BatchNorm2d(out))) {}
  torch::Tensor forward(const torch::Tensor& x) { return torch::relu(bn(conv(x))); }
  torch::nn::Conv2d conv;
  torch::nn::BatchNorm2d bn;
};
TORCH_MODULE(ConvBn);

torch::nn::Conv2d pointwise(int in, int out) {
  return torch::nn::Conv2d(torch::nn::Conv2dOptions(in, out, 1));
}

torch::Tensor upsample2(const torch::Tensor& x) {
  namespace F = torch::nn::functional;
  return F::interpolate(x, F::InterpolateFuncOptions()
                               .scale_factor(std::vector<double>{2.0, 2.0})
                               .mode(torch::kBilinear)
                               .align_corners(false));
}

// Encoder to 1/8 (16, 32, 64 channels), three dilated convolutions there for context, class
// logits at 1/8 refined by 1x1 projections of the 1/4 and 1/2 features (thin poles and signs
// survive only at the finer scales). Logits at 1/2 of the input.
struct SegNetImpl : torch::nn::Module {
  SegNetImpl()
      : e1(register_module("e1", ConvBn(3, 16, 2, 1))),
        e2(register_module("e2", ConvBn(16, 32, 2, 1))),
        e3(register_module("e3", ConvBn(32, 64, 2, 1))),
        c1(register_module("c1", ConvBn(64, 64, 1, 1))),
        c2(register_module("c2", ConvBn(64, 64, 1, 2))),
        c3(register_module("c3", ConvBn(64, 64, 1, 4))),
        head8(register_module("head8", pointwise(64, kSegmentationClasses))),
        skip4(register_module("skip4", pointwise(32, kSegmentationClasses))),
        skip2(register_module("skip2", pointwise(16, kSegmentationClasses))) {}

  torch::Tensor forward(const torch::Tensor& x) {
    const torch::Tensor half = e1(x), quarter = e2(half);
    const torch::Tensor eighth = c3(c2(c1(e3(quarter))));
    torch::Tensor logits = upsample2(head8(eighth)) + skip4(quarter);
    return upsample2(logits) + skip2(half);
  }

  ConvBn e1, e2, e3, c1, c2, c3;
  torch::nn::Conv2d head8, skip4, skip2;
};
TORCH_MODULE(SegNet);

std::vector<float> toVector(const torch::Tensor& t) {
  const torch::Tensor c = t.contiguous().to(torch::kFloat32);
  return std::vector<float>(c.data_ptr<float>(), c.data_ptr<float>() + c.numel());
}

OnnxConv folded(const ConvBn& m) {
  const auto& o = m->conv->options;
  const torch::Tensor scale =
      m->bn->weight / torch::sqrt(m->bn->running_var + m->bn->options.eps());
  OnnxConv c;
  c.in_channels = static_cast<int>(o.in_channels());
  c.out_channels = static_cast<int>(o.out_channels());
  c.kernel = static_cast<int>(o.kernel_size()->at(0));
  c.stride = static_cast<int>(o.stride()->at(0));
  c.dilation = static_cast<int>(o.dilation()->at(0));
  c.weight = toVector(m->conv->weight * scale.view({-1, 1, 1, 1}));
  c.bias = toVector(m->bn->bias - m->bn->running_mean * scale);
  return c;
}

OnnxConv plain(const torch::nn::Conv2d& m) {
  OnnxConv c;
  c.in_channels = static_cast<int>(m->options.in_channels());
  c.out_channels = static_cast<int>(m->options.out_channels());
  c.weight = toVector(m->weight);
  c.bias = toVector(m->bias);
  return c;
}

std::string exportOnnx(SegNet& net) {
  torch::NoGradGuard no_grad;
  OnnxGraph g;
  auto block = [&](const std::string& x, const ConvBn& m) { return g.relu(g.conv(x, folded(m))); };
  const std::string half = block(g.input(), net->e1), quarter = block(half, net->e2);
  std::string eighth = block(quarter, net->e3);
  for (const ConvBn& m : {net->c1, net->c2, net->c3}) eighth = block(eighth, m);
  std::string logits =
      g.add(g.upsample2(g.conv(eighth, plain(net->head8))), g.conv(quarter, plain(net->skip4)));
  logits = g.add(g.upsample2(logits), g.conv(half, plain(net->skip2)));
  return g.serialize(logits, kSegmentationClasses, "semsegmap train-segmentation");
}

// Brightness, contrast and colour of a crop, as the two lighting conditions and the camera's
// exposure vary them.
struct Jitter {
  float gain[3] = {1, 1, 1};
  float offset = 0;
};

Jitter drawJitter(std::mt19937_64& rng) {
  std::uniform_real_distribution<float> contrast(0.75f, 1.25f), tint(0.93f, 1.07f),
      shift(-0.1f, 0.1f);
  Jitter j;
  const float c = contrast(rng);
  for (float& g : j.gain) g = c * tint(rng);
  j.offset = shift(rng);
  return j;
}

struct Crop {
  int x = 0, y = 0, width = 0, height = 0;
  bool flip = false;
  Jitter jitter;
};

// One crop into batch slot `slot` of x (B x 3 x h x w, normalised) and y (B x h x w class ids).
void fillSlot(const LabelledPicture& p, const Crop& c, const SegTrainConfig& config, int slot,
              torch::Tensor& x, torch::Tensor& y) {
  float* xs = x.data_ptr<float>() + static_cast<size_t>(slot) * 3 * c.width * c.height;
  int64_t* ys = y.data_ptr<int64_t>() + static_cast<size_t>(slot) * c.width * c.height;
  const size_t plane = static_cast<size_t>(c.width) * c.height;
  for (int r = 0; r < c.height; ++r) {
    for (int col = 0; col < c.width; ++col) {
      const int sx = c.x + (c.flip ? c.width - 1 - col : col), sy = c.y + r;
      const uint8_t* px = p.rgb.at(sx, sy);
      const size_t i = static_cast<size_t>(r) * c.width + col;
      for (int k = 0; k < 3; ++k) {
        const float v = std::clamp(px[k] / 255.f * c.jitter.gain[k] + c.jitter.offset, 0.f, 1.f);
        xs[k * plane + i] = (v - config.mean[k]) / config.std[k];
      }
      ys[i] = *p.label.at(sx, sy);
    }
  }
}

struct Batch {
  torch::Tensor x, y;
};

Batch randomBatch(const std::vector<const LabelledPicture*>& pictures,
                  const std::vector<size_t>& which, const SegTrainConfig& config,
                  std::mt19937_64& rng) {
  const int b = static_cast<int>(which.size()), w = config.crop_width, h = config.crop_height;
  Batch batch{torch::empty({b, 3, h, w}), torch::empty({b, h, w}, torch::kInt64)};
  for (int i = 0; i < b; ++i) {
    Crop c{0, 0, w, h, false, {}};
    c.x = std::uniform_int_distribution<int>(0, config.input_width - w)(rng);
    c.y = std::uniform_int_distribution<int>(0, config.input_height - h)(rng);
    c.flip = std::bernoulli_distribution(0.5)(rng);
    c.jitter = drawJitter(rng);
    fillSlot(*pictures[which[i]], c, config, i, batch.x, batch.y);
  }
  return batch;
}

Batch wholePicture(const LabelledPicture& p, const SegTrainConfig& config) {
  const int w = config.input_width, h = config.input_height;
  Batch batch{torch::empty({1, 3, h, w}), torch::empty({1, h, w}, torch::kInt64)};
  fillSlot(p, Crop{0, 0, w, h, false, {}}, config, 0, batch.x, batch.y);
  return batch;
}

torch::Tensor fullSizeLogits(SegNet& net, const torch::Tensor& x) {
  namespace F = torch::nn::functional;
  return F::interpolate(net->forward(x), F::InterpolateFuncOptions()
                                             .size(std::vector<int64_t>{x.size(2), x.size(3)})
                                             .mode(torch::kBilinear)
                                             .align_corners(false));
}

}  // namespace

namespace {

void checkShrink(const Image& image, int channels, int width, int height) {
  if (image.channels != channels || width < 1 || height < 1 || width > image.width ||
      height > image.height)
    throw std::invalid_argument(
        "cannot shrink a " + std::to_string(image.width) + "x" + std::to_string(image.height) +
        "x" + std::to_string(image.channels) + " image to " + std::to_string(width) + "x" +
        std::to_string(height) + "x" + std::to_string(channels));
}

// The source pixels [first, last) that destination pixel i of n covers along an axis of size s.
std::pair<int, int> covered(int i, int n, int s) {
  const int first = static_cast<int>(static_cast<int64_t>(i) * s / n);
  const int last = static_cast<int>(static_cast<int64_t>(i + 1) * s / n);
  return {first, std::max(last, first + 1)};
}

}  // namespace

Image shrinkPicture(const Image& rgb, int width, int height) {
  checkShrink(rgb, 3, width, height);
  Image out(width, height, 3);
  for (int y = 0; y < height; ++y) {
    const auto [y0, y1] = covered(y, height, rgb.height);
    for (int x = 0; x < width; ++x) {
      const auto [x0, x1] = covered(x, width, rgb.width);
      int sum[3] = {0, 0, 0};
      for (int sy = y0; sy < y1; ++sy)
        for (int sx = x0; sx < x1; ++sx)
          for (int k = 0; k < 3; ++k) sum[k] += rgb.at(sx, sy)[k];
      const int n = (y1 - y0) * (x1 - x0);
      for (int k = 0; k < 3; ++k) out.at(x, y)[k] = static_cast<uint8_t>((sum[k] + n / 2) / n);
    }
  }
  return out;
}

Image shrinkLabels(const Image& label, int width, int height) {
  checkShrink(label, 1, width, height);
  Image out(width, height, 1);
  for (int y = 0; y < height; ++y) {
    const int sy = static_cast<int>((y + 0.5) * label.height / height);
    for (int x = 0; x < width; ++x)
      *out.at(x, y) = *label.at(static_cast<int>((x + 0.5) * label.width / width), sy);
  }
  return out;
}

namespace {

void checkInputs(const std::vector<LabelledPicture>& pictures, const SegTrainConfig& c) {
  if (pictures.empty()) throw std::invalid_argument("no pictures to train on");
  for (int v : {c.input_width, c.input_height, c.crop_width, c.crop_height})
    if (v < 8 || v % 8 != 0)
      throw std::invalid_argument("input and crop sizes must be multiples of 8, got " +
                                  std::to_string(v));
  if (c.crop_width > c.input_width || c.crop_height > c.input_height)
    throw std::invalid_argument("the crop is larger than the input");
  for (size_t i = 0; i < pictures.size(); ++i) {
    const LabelledPicture& p = pictures[i];
    if (p.rgb.width != c.input_width || p.rgb.height != c.input_height || p.rgb.channels != 3 ||
        p.label.width != c.input_width || p.label.height != c.input_height || p.label.channels != 1)
      throw std::invalid_argument("picture " + std::to_string(i) + " is not " +
                                  std::to_string(c.input_width) + "x" +
                                  std::to_string(c.input_height) + " RGB with a label image");
  }
}

// ENet's weights 1 / ln(c + share) over the labelled pixels; classes never seen get the
// largest weight (they cost nothing), unknown 0.
std::array<double, kSegmentationClasses> classWeights(
    const std::vector<const LabelledPicture*>& pictures, double c) {
  std::array<double, kSegmentationClasses> count{};
  for (const LabelledPicture* p : pictures)
    for (uint8_t id : p->label.data)
      if (id < kSegmentationClasses) count[id] += 1;
  count[cls::kUnknown] = 0;
  double total = 0;
  for (double n : count) total += n;
  std::array<double, kSegmentationClasses> w{};
  for (int k = 1; k < kSegmentationClasses; ++k)
    w[k] = 1.0 / std::log(c + (total > 0 ? count[k] / total : 0.0));
  return w;
}

struct Validation {
  double accuracy = 0, miou = 0;
};

Validation validate(SegNet& net, const std::vector<const LabelledPicture*>& pictures,
                    const SegTrainConfig& config) {
  if (pictures.empty()) return {};
  torch::NoGradGuard no_grad;
  net->eval();
  std::vector<double> confusion(kSegmentationClasses * kSegmentationClasses, 0.0);
  for (const LabelledPicture* p : pictures) {
    const Batch b = wholePicture(*p, config);
    const torch::Tensor predicted = fullSizeLogits(net, b.x).argmax(1).flatten();
    const torch::Tensor truth = b.y.flatten();
    const int64_t* t = truth.data_ptr<int64_t>();
    const int64_t* q = predicted.data_ptr<int64_t>();
    for (int64_t i = 0; i < truth.numel(); ++i)
      if (t[i] != cls::kUnknown && t[i] < kSegmentationClasses)
        confusion[t[i] * kSegmentationClasses + q[i]] += 1;
  }
  net->train();
  double correct = 0, total = 0, iou_sum = 0;
  int classes = 0;
  for (int k = 1; k < kSegmentationClasses; ++k) {
    double truth = 0, predicted = 0;
    for (int j = 0; j < kSegmentationClasses; ++j) {
      truth += confusion[k * kSegmentationClasses + j];
      predicted += confusion[j * kSegmentationClasses + k];
    }
    const double tp = confusion[k * kSegmentationClasses + k];
    correct += tp;
    total += truth;
    if (truth > 0) iou_sum += tp / (truth + predicted - tp), ++classes;
  }
  return {total > 0 ? correct / total : 0.0, classes ? iou_sum / classes : 0.0};
}

}  // namespace

namespace {

constexpr size_t kMaxValidationPictures = 150;  // enough for the curve, a few seconds an epoch

// Every k-th picture is held out (evenly over the runs the list holds, one after another).
void split(const std::vector<LabelledPicture>& pictures, double fraction,
           std::vector<const LabelledPicture*>& train, std::vector<const LabelledPicture*>& held) {
  for (size_t i = 0; i < pictures.size(); ++i) {
    const bool out =
        pictures.size() > 1 && std::floor((i + 1) * fraction) > std::floor(i * fraction);
    (out ? held : train).push_back(&pictures[i]);
  }
  if (held.size() <= kMaxValidationPictures) return;
  std::vector<const LabelledPicture*> kept;
  for (size_t k = 0; k < kMaxValidationPictures; ++k)
    kept.push_back(held[k * held.size() / kMaxValidationPictures]);
  held = std::move(kept);
}

// Cosine decay from the base rate to 2 % of it over the whole run.
double learningRate(const SegTrainConfig& c, int64_t step, int64_t steps) {
  const double t = steps > 1 ? static_cast<double>(step) / (steps - 1) : 1.0;
  return c.learning_rate * (0.02 + 0.98 * 0.5 * (1.0 + std::cos(M_PI * t)));
}

struct StepResult {
  double loss = 0, correct = 0, labelled = 0;
};

StepResult trainStep(SegNet& net, torch::optim::Adam& adam, const Batch& b,
                     const torch::Tensor& weights) {
  namespace F = torch::nn::functional;
  const torch::Tensor logits = fullSizeLogits(net, b.x);
  const torch::Tensor loss = F::cross_entropy(
      logits, b.y, F::CrossEntropyFuncOptions().weight(weights).ignore_index(cls::kUnknown));
  adam.zero_grad();
  loss.backward();
  adam.step();
  const torch::Tensor labelled = b.y != cls::kUnknown;
  const torch::Tensor correct = (logits.argmax(1) == b.y) & labelled;
  return {loss.item<double>(), correct.sum().item<double>(), labelled.sum().item<double>()};
}

std::function<std::vector<float>(const Image&, int&, int&)> torchLogits(SegNet net,
                                                                        SegTrainConfig config) {
  return [net, config](const Image& rgb, int& h, int& w) mutable {
    torch::NoGradGuard no_grad;
    net->eval();
    LabelledPicture p{rgb, Image(rgb.width, rgb.height, 1)};
    config.input_width = rgb.width;
    config.input_height = rgb.height;
    const torch::Tensor out = net->forward(wholePicture(p, config).x);
    h = static_cast<int>(out.size(2));
    w = static_cast<int>(out.size(3));
    return toVector(out);
  };
}

}  // namespace

SegTrainResult trainSegmentation(const std::vector<LabelledPicture>& pictures,
                                 const SegTrainConfig& config, const SegTrainCallbacks& callbacks) {
  checkInputs(pictures, config);
  torch::set_num_threads(config.threads);
  torch::manual_seed(config.seed);
  std::mt19937_64 rng(config.seed);
  std::vector<const LabelledPicture*> train, held;
  split(pictures, config.validation_fraction, train, held);
  SegTrainResult result;
  result.train_pictures = train.size();
  result.validation_pictures = held.size();
  result.class_weights = classWeights(train, config.class_weight_c);
  const torch::Tensor weights =
      torch::tensor(std::vector<double>(result.class_weights.begin(), result.class_weights.end()))
          .to(torch::kFloat32);
  SegNet net;
  torch::optim::Adam adam(
      net->parameters(),
      torch::optim::AdamOptions(config.learning_rate).weight_decay(config.weight_decay));
  const int64_t steps_per_epoch = std::max<int64_t>(
      1, (static_cast<int64_t>(train.size()) + config.batch_size - 1) / config.batch_size);
  const int64_t steps = steps_per_epoch * config.epochs;
  const auto start = std::chrono::steady_clock::now();
  for (int epoch = 1; epoch <= config.epochs && !result.interrupted; ++epoch) {
    std::vector<size_t> order(train.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), rng);
    StepResult sum;
    int64_t done = 0;
    double lr = 0;
    for (; done < steps_per_epoch; ++done) {
      if (callbacks.stop.stopRequested()) {
        result.interrupted = true;
        break;
      }
      lr = learningRate(config, (epoch - 1) * steps_per_epoch + done, steps);
      static_cast<torch::optim::AdamOptions&>(adam.param_groups()[0].options()).lr(lr);
      std::vector<size_t> which;
      for (int k = 0; k < config.batch_size; ++k)
        which.push_back(order[(done * config.batch_size + k) % order.size()]);
      const StepResult s = trainStep(net, adam, randomBatch(train, which, config, rng), weights);
      sum.loss += s.loss, sum.correct += s.correct, sum.labelled += s.labelled;
      if (callbacks.step)
        callbacks.step(epoch, static_cast<int>(done + 1), static_cast<int>(steps_per_epoch),
                       sum.loss / (done + 1));
    }
    if (done == 0) break;
    const Validation v = validate(net, held, config);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.history.push_back({epoch, sum.loss / done,
                              sum.labelled > 0 ? sum.correct / sum.labelled : 0.0, v.accuracy,
                              v.miou, lr, seconds});
    if (callbacks.epoch) callbacks.epoch(result.history.back());
  }
  net->eval();
  result.onnx = exportOnnx(net);
  result.torch_logits = torchLogits(net, config);
  return result;
}

}  // namespace semsegmap
