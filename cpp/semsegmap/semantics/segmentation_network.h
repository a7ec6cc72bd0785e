// The camera segmentation network (the paper's first step: "the color images are passed through
// a semantic segmentation network"): a network exported to ONNX, run on the CPU through OpenCV's
// DNN module, turns an RGB picture into a label image in the project's classes through a class
// map. The one shipped network (models/semsegmap-seg.onnx, `semsegmap train-segmentation`) is
// trained on the simulator and is for simulated data; docs/real-data.md, "Semantics from a
// network", says how to export one for real pictures and which class map goes with it.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "semsegmap/core/image.h"
#include "semsegmap/semantics/class_map.h"

namespace cv {
class Mat;  // OpenCV stays out of this header: a consumer of the stage needs no OpenCV headers
}

namespace semsegmap {

// How a picture is brought to the network's input size, and the labels back to the picture.
enum class ResizePolicy {
  kStretch,     // both axes scaled independently (the aspect ratio may change)
  kLetterbox,   // scaled to fit, padded with the mean colour; the padding's labels are dropped
  kCenterCrop,  // scaled to cover, the middle cut out; pixels outside it get class unknown
};
enum class NetworkOutput {
  kLogits,  // N x C x h x w scores, any h x w (resized to the input bilinearly, then argmax)
  kArgmax,  // N x 1 x h x w (or N x h x w) class ids
};

struct SemanticsConfig {
  std::string model;  // ONNX file; empty: no network. In YAML relative to the config file.
  // The network's class ids -> the project's: a shipped map's name (cityscapes, ade20k; see
  // config/class_maps/) or a YAML file (relative to the config file).
  std::string class_map = "cityscapes";
  int input_width = 0, input_height = 0;  // 0: the picture's own size
  ResizePolicy resize = ResizePolicy::kStretch;
  // Normalisation of pixel values scaled to [0, 1], per channel in RGB order: (v - mean) / std.
  // The defaults are ImageNet's, which most segmentation toolkits train with.
  std::array<float, 3> mean{0.485f, 0.456f, 0.406f};
  std::array<float, 3> std{0.229f, 0.224f, 0.225f};
  bool bgr = false;  // the network takes BGR channels (Caffe and OpenCV-trained models)
  NetworkOutput output = NetworkOutput::kLogits;
  int threads = 2;  // OpenCV's threads while the network runs (given back after each picture)
  // The network on a budget (semantics/label_schedule.h): it labels at most rate_hz pictures a
  // second per camera (0: no limit) and uses at most budget_cores of the machine's cores on
  // average (0: no limit); a scan takes each camera's newest labels at most tolerance_s older
  // than itself, carried by odometry, or none. All three 0 (with latency_s): every picture is
  // labelled and every scan takes its own pictures' labels.
  double rate_hz = 0.0;
  double budget_cores = 0.0;
  double tolerance_s = 0.5;
  // A recording replays the budget deterministically with this as the network's time per picture
  // (seconds on `threads` threads; measure it with BM_SegmentationNetwork), so that the same
  // inputs give the same files. On a robot the network's own time counts instead.
  double latency_s = 0.0;
  // Run the network on pictures that already have label images too (e.g. to measure a network
  // against the simulator's perfect labels); normally dataset labels are kept.
  bool replace_dataset_labels = false;
};

ResizePolicy parseResizePolicy(const std::string& name);    // stretch | letterbox | crop
NetworkOutput parseNetworkOutput(const std::string& name);  // logits | argmax

class SegmentationNetwork {
 public:
  // `onnx` holds the model file's bytes, `model_name` names it in errors. Throws
  // std::runtime_error "<model_name>: ..." when OpenCV cannot read it.
  SegmentationNetwork(const SemanticsConfig& config, const std::string& onnx, ClassMap class_map,
                      std::string model_name);
  ~SegmentationNetwork();
  SegmentationNetwork(const SegmentationNetwork&) = delete;
  SegmentationNetwork& operator=(const SegmentationNetwork&) = delete;

  // Runs the network once on a blank picture of this size, so that errors come before the work:
  // a model that refuses the input size, an output of the wrong layout, logits with a class the
  // class map does not list. Throws std::runtime_error "<model_name>: ...".
  void check(int width, int height);
  // The label image (project ids, the picture's size) of an RGB picture; `what` names the
  // picture in errors (an argmax output id the class map does not list).
  Image label(const Image& rgb, const std::string& what);
  // Output classes of a logits network, once check() or label() ran; 0 for argmax output.
  int outputClasses() const;
  const SemanticsConfig& config() const { return config_; }

 private:
  void adoptOutput(const cv::Mat& out);
  void labelFromLogits(const cv::Mat& out, const std::vector<float>& u, const std::vector<float>& v,
                       Image& labels) const;
  void labelFromArgmax(const cv::Mat& out, const std::vector<float>& u, const std::vector<float>& v,
                       Image& labels, const std::string& what) const;

  struct Impl;
  SemanticsConfig config_;
  ClassMap class_map_;
  std::string model_name_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace semsegmap
