#include "semsegmap/semantics/segmentation_network.h"

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace semsegmap {

namespace {

// Where the picture lies on the network's input canvas: scaled to `scaled` and placed at
// `offset` (negative when the canvas cuts it, as a centre crop does).
struct Placement {
  cv::Size canvas, scaled;
  cv::Point offset;
};

Placement placePicture(ResizePolicy policy, cv::Size picture, cv::Size canvas) {
  const double sx = static_cast<double>(canvas.width) / picture.width;
  const double sy = static_cast<double>(canvas.height) / picture.height;
  if (policy == ResizePolicy::kStretch) return {canvas, canvas, {0, 0}};
  const double s = policy == ResizePolicy::kLetterbox ? std::min(sx, sy) : std::max(sx, sy);
  const cv::Size scaled(std::max(1, static_cast<int>(std::lround(picture.width * s))),
                        std::max(1, static_cast<int>(std::lround(picture.height * s))));
  return {canvas, scaled, {(canvas.width - scaled.width) / 2, (canvas.height - scaled.height) / 2}};
}

// One line from an OpenCV error (its what() spans lines and names OpenCV's source files).
std::string openCvMessage(const cv::Exception& e) {
  return "OpenCV: " + e.err + (e.func.empty() ? "" : " in " + e.func);
}

// OpenCV's DNN logs a multi-line trace of a failing layer before throwing; the error we raise
// says it in one line, so its log is off while the network runs.
class QuietOpenCv {
 public:
  QuietOpenCv() : level_(cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT)) {}
  ~QuietOpenCv() { cv::utils::logging::setLogLevel(level_); }

 private:
  cv::utils::logging::LogLevel level_;
};

// OpenCV's thread count is the process's: set for the network's run only, then given back, so
// that a caller's own setting (or another network's) is never changed behind its back.
class OpenCvThreads {
 public:
  explicit OpenCvThreads(int threads) : saved_(cv::getNumThreads()), set_(threads > 0) {
    if (set_) cv::setNumThreads(threads);
  }
  ~OpenCvThreads() {
    if (set_) cv::setNumThreads(saved_);
  }
  OpenCvThreads(const OpenCvThreads&) = delete;
  OpenCvThreads& operator=(const OpenCvThreads&) = delete;

 private:
  int saved_;
  bool set_;
};

}  // namespace

ResizePolicy parseResizePolicy(const std::string& name) {
  if (name == "stretch") return ResizePolicy::kStretch;
  if (name == "letterbox") return ResizePolicy::kLetterbox;
  if (name == "crop") return ResizePolicy::kCenterCrop;
  throw std::invalid_argument("expected stretch, letterbox or crop, got '" + name + "'");
}

NetworkOutput parseNetworkOutput(const std::string& name) {
  if (name == "logits") return NetworkOutput::kLogits;
  if (name == "argmax") return NetworkOutput::kArgmax;
  throw std::invalid_argument("expected logits or argmax, got '" + name + "'");
}

struct SegmentationNetwork::Impl {
  cv::dnn::Net net;
  int classes = 0;              // logits channels, once known
  std::vector<ClassId> target;  // by output class, for logits
};

SegmentationNetwork::SegmentationNetwork(const SemanticsConfig& config, const std::string& onnx,
                                         ClassMap class_map, std::string model_name)
    : config_(config),
      class_map_(std::move(class_map)),
      model_name_(std::move(model_name)),
      impl_(std::make_unique<Impl>()) {
  try {
    QuietOpenCv quiet;
    impl_->net = cv::dnn::readNetFromONNX(onnx.data(), onnx.size());
  } catch (const cv::Exception& e) {
    throw std::runtime_error(model_name_ + ": not a readable ONNX model (" + openCvMessage(e) +
                             ")");
  }
  if (impl_->net.empty()) throw std::runtime_error(model_name_ + ": the ONNX model has no layers");
  impl_->net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  impl_->net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
}

SegmentationNetwork::~SegmentationNetwork() = default;

int SegmentationNetwork::outputClasses() const {
  return impl_->classes;
}

namespace {

// The picture scaled and normalised on the network's canvas, as an N x 3 x H x W blob. The
// canvas outside the picture holds the mean colour (0 after normalisation).
cv::Mat inputBlob(const Image& rgb, const SemanticsConfig& c, const Placement& p) {
  const cv::Mat picture(rgb.height, rgb.width, CV_8UC3, const_cast<uint8_t*>(rgb.data.data()));
  cv::Mat scaled, as_float;
  const bool shrinking = p.scaled.width < rgb.width;
  cv::resize(picture, scaled, p.scaled, 0, 0, shrinking ? cv::INTER_AREA : cv::INTER_LINEAR);
  scaled.convertTo(as_float, CV_32FC3, 1.0 / 255.0);
  std::vector<cv::Mat> channels(3);
  cv::split(as_float, channels);
  for (int k = 0; k < 3; ++k) channels[k] = (channels[k] - c.mean[k]) / c.std[k];
  if (c.bgr) std::swap(channels[0], channels[2]);
  cv::merge(channels, as_float);
  cv::Mat canvas(p.canvas, CV_32FC3, cv::Scalar::all(0));
  const cv::Rect overlap = cv::Rect(p.offset, p.scaled) & cv::Rect(cv::Point(0, 0), p.canvas);
  as_float(cv::Rect(overlap.tl() - p.offset, overlap.size())).copyTo(canvas(overlap));
  return cv::dnn::blobFromImage(canvas);
}

std::string shapeText(const cv::Mat& m) {
  std::string s;
  for (int d = 0; d < m.dims; ++d) s += (d ? "x" : "") + std::to_string(m.size[d]);
  return s;
}

// A picture pixel's coordinate on the output grid along one axis: picture -> scaled picture ->
// canvas -> output, pixel centres aligned at each step. NaN when the canvas does not hold it.
float outputCoordinate(int x, int picture, int scaled, int offset, int canvas, int output) {
  const double on_canvas = (x + 0.5) * scaled / picture - 0.5 + offset;
  if (on_canvas < -0.5 || on_canvas > canvas - 0.5) return std::nanf("");
  return static_cast<float>((on_canvas + 0.5) * output / canvas - 0.5);
}

std::vector<float> outputCoordinates(int n, int picture, int scaled, int offset, int canvas,
                                     int output) {
  std::vector<float> u(static_cast<size_t>(n));
  for (int x = 0; x < n; ++x) u[x] = outputCoordinate(x, picture, scaled, offset, canvas, output);
  return u;
}

}  // namespace

namespace {

cv::Mat runNetwork(cv::dnn::Net& net, const Image& rgb, const SemanticsConfig& c,
                   const std::string& model, Placement& placement) {
  const cv::Size picture(rgb.width, rgb.height);
  if (picture.width <= 0 || picture.height <= 0)
    throw std::runtime_error(model + ": cannot label a picture of " + std::to_string(rgb.width) +
                             "x" + std::to_string(rgb.height) + " pixels");
  const cv::Size canvas =
      c.input_width > 0 && c.input_height > 0 ? cv::Size(c.input_width, c.input_height) : picture;
  placement = placePicture(c.resize, picture, canvas);
  const cv::Mat blob = inputBlob(rgb, c, placement);
  try {
    QuietOpenCv quiet;
    OpenCvThreads threads(c.threads);
    net.setInput(blob);
    return net.forward().clone();
  } catch (const cv::Exception& e) {
    throw std::runtime_error(model + ": refuses a " + shapeText(blob) + " input (" +
                             openCvMessage(e) + "); set semantics.input_width/input_height to " +
                             "the size it was exported with");
  }
}

}  // namespace

// Checks the output's layout against the config; for logits, learns the classes and checks the
// class map lists every one.
void SegmentationNetwork::adoptOutput(const cv::Mat& out) {
  const bool argmax = config_.output == NetworkOutput::kArgmax;
  const bool logits_ok = out.dims == 4 && out.size[0] == 1 && out.size[1] >= 1;
  const bool argmax_ok = (out.dims == 4 && out.size[0] == 1 && out.size[1] == 1) ||
                         (out.dims == 3 && out.size[0] == 1);
  if (argmax ? !argmax_ok : !logits_ok)
    throw std::runtime_error(model_name_ + ": an output of shape " + shapeText(out) +
                             (argmax ? " is not an argmax map (1 x 1 x h x w or 1 x h x w)"
                                     : " is not logits (1 x classes x h x w)"));
  if (out.type() != CV_32F)
    throw std::runtime_error(model_name_ + ": output of OpenCV type " + std::to_string(out.type()) +
                             ", expected float");
  if (argmax || impl_->classes == out.size[1]) return;
  const int classes = out.size[1];
  if (const auto missing = class_map_.firstMissing(classes))
    throw std::runtime_error(model_name_ + ": network class " + std::to_string(*missing) + " (of " +
                             std::to_string(classes) + ") is not in class map " +
                             class_map_.name() + ", which must list every output class");
  impl_->target.resize(static_cast<size_t>(classes));
  for (int c = 0; c < classes; ++c) impl_->target[c] = *class_map_.find(c);
  impl_->classes = classes;
}

void SegmentationNetwork::check(int width, int height) {
  Placement placement;
  adoptOutput(runNetwork(impl_->net, Image(width, height, 3), config_, model_name_, placement));
}

Image SegmentationNetwork::label(const Image& rgb, const std::string& what) {
  if (rgb.channels != 3 || rgb.empty())
    throw std::runtime_error(what + ": the network needs an RGB picture, this one has " +
                             std::to_string(rgb.channels) + " channels");
  Placement p;
  const cv::Mat out = runNetwork(impl_->net, rgb, config_, model_name_, p);
  adoptOutput(out);
  const int oh = out.size[out.dims - 2], ow = out.size[out.dims - 1];
  const std::vector<float> u =
      outputCoordinates(rgb.width, rgb.width, p.scaled.width, p.offset.x, p.canvas.width, ow);
  const std::vector<float> v =
      outputCoordinates(rgb.height, rgb.height, p.scaled.height, p.offset.y, p.canvas.height, oh);
  Image labels(rgb.width, rgb.height, 1, cls::kUnknown);
  if (config_.output == NetworkOutput::kLogits)
    labelFromLogits(out, u, v, labels);
  else
    labelFromArgmax(out, u, v, labels, what);
  return labels;
}

// Scores sampled bilinearly at each picture pixel (the output may be coarser than the picture),
// then the best class. Pixels the canvas cut off (centre crop) stay unknown.
void SegmentationNetwork::labelFromLogits(const cv::Mat& out, const std::vector<float>& u,
                                          const std::vector<float>& v, Image& labels) const {
  const int classes = out.size[1], oh = out.size[2], ow = out.size[3];
  const size_t plane = static_cast<size_t>(oh) * ow;
  const float* scores = out.ptr<float>();
  for (int y = 0; y < labels.height; ++y) {
    if (std::isnan(v[y])) continue;
    const float fy = std::clamp(v[y], 0.0f, static_cast<float>(oh - 1));
    const int y0 = static_cast<int>(fy), y1 = std::min(y0 + 1, oh - 1);
    const float wy = fy - y0;
    for (int x = 0; x < labels.width; ++x) {
      if (std::isnan(u[x])) continue;
      const float fx = std::clamp(u[x], 0.0f, static_cast<float>(ow - 1));
      const int x0 = static_cast<int>(fx), x1 = std::min(x0 + 1, ow - 1);
      const float wx = fx - x0;
      const size_t i00 = static_cast<size_t>(y0) * ow + x0, i01 = static_cast<size_t>(y0) * ow + x1;
      const size_t i10 = static_cast<size_t>(y1) * ow + x0, i11 = static_cast<size_t>(y1) * ow + x1;
      int best = 0;
      float best_score = -std::numeric_limits<float>::infinity();
      for (int c = 0; c < classes; ++c) {
        const float* s = scores + c * plane;
        const float top = s[i00] + wx * (s[i01] - s[i00]);
        const float bottom = s[i10] + wx * (s[i11] - s[i10]);
        const float score = top + wy * (bottom - top);
        if (score > best_score) best_score = score, best = c;
      }
      *labels.at(x, y) = static_cast<uint8_t>(impl_->target[best]);
    }
  }
}

// The nearest output pixel's class id, through the class map.
void SegmentationNetwork::labelFromArgmax(const cv::Mat& out, const std::vector<float>& u,
                                          const std::vector<float>& v, Image& labels,
                                          const std::string& what) const {
  const int oh = out.size[out.dims - 2], ow = out.size[out.dims - 1];
  const float* ids = out.ptr<float>();
  for (int y = 0; y < labels.height; ++y) {
    if (std::isnan(v[y])) continue;
    const int yo = std::clamp(static_cast<int>(std::lround(v[y])), 0, oh - 1);
    for (int x = 0; x < labels.width; ++x) {
      if (std::isnan(u[x])) continue;
      const int xo = std::clamp(static_cast<int>(std::lround(u[x])), 0, ow - 1);
      const float id = ids[static_cast<size_t>(yo) * ow + xo];
      const std::optional<ClassId> to = class_map_.find(static_cast<int>(id));
      if (!to || id != std::floor(id))
        throw std::runtime_error(what + ": pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                                 ") has network class " + std::to_string(id) +
                                 ", which class map " + class_map_.name() + " does not list");
      *labels.at(x, y) = static_cast<uint8_t>(*to);
    }
  }
}

}  // namespace semsegmap
