// Training of the project's camera segmentation network on the simulator's pictures and label
// images (`semsegmap train-segmentation`): a small fully convolutional encoder-decoder in
// libtorch, class-weighted cross entropy on random crops, exported to ONNX (learn/onnx_writer.h)
// with its batch norms folded into the convolutions, so that the semantics stage
// (semantics/segmentation_network.h) runs it through OpenCV like any other network. Its output
// channel c is the project's class id c (class map "semsegmap").
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "semsegmap/core/class_table.h"
#include "semsegmap/core/image.h"
#include "semsegmap/core/stop_token.h"

namespace semsegmap {

// A picture and its label image (project class ids, class unknown ignored), the same size.
struct LabelledPicture {
  Image rgb;
  Image label;
};

// `rgb` (3 channels) shrunk to width x height by averaging the pixels each covers (OpenCV's
// INTER_AREA for whole factors, as the semantics stage shrinks pictures), and a label image by
// nearest neighbour. Throws std::invalid_argument when the target is larger than the image.
Image shrinkPicture(const Image& rgb, int width, int height);
Image shrinkLabels(const Image& label, int width, int height);

// Output channels: one per project class id, unknown (0) to sky.
constexpr int kSegmentationClasses = cls::kSky + 1;

struct SegTrainConfig {
  // The pictures' size, the network's input size; crops are what a step sees of a picture. All
  // multiples of 8 (three stride-2 convolutions).
  int input_width = 320, input_height = 240;
  int crop_width = 192, crop_height = 144;
  int epochs = 16;
  int batch_size = 12;
  double learning_rate = 3e-3;  // Adam, decayed along a cosine to 2 % of it
  double weight_decay = 1e-4;
  // Class weights 1 / ln(c + f) of the classes' pixel shares f (ENet's), so that thin classes
  // (pole, traffic sign, trunk, person) weigh several times the road.
  double class_weight_c = 1.02;
  double validation_fraction = 0.1;  // of the pictures, held out (every 10th)
  // Normalisation of [0, 1] pixel values, RGB order: the semantics stage's defaults (ImageNet's).
  std::array<float, 3> mean{0.485f, 0.456f, 0.406f};
  std::array<float, 3> std{0.229f, 0.224f, 0.225f};
  int threads = 2;
  uint64_t seed = 1;
};

struct SegEpochStats {
  int epoch = 0;
  double loss = 0;            // mean training loss of the epoch
  double train_accuracy = 0;  // pixel accuracy on the epoch's crops
  double val_accuracy = 0;    // on the held-out pictures at the input size
  double val_miou = 0;        // over the classes in the held-out truth (unknown left out)
  double learning_rate = 0;   // at the epoch's end
  double seconds = 0;
};

struct SegTrainCallbacks {
  std::function<void(int epoch, int step, int steps, double loss)> step;
  std::function<void(const SegEpochStats&)> epoch;
  StopToken stop;  // checked between steps; the model so far is exported
};

struct SegTrainResult {
  std::vector<SegEpochStats> history;
  size_t train_pictures = 0, validation_pictures = 0;
  std::array<double, kSegmentationClasses> class_weights{};
  std::string onnx;  // the model's bytes (class logits at 1/2 of the input size)
  // The trained network's logits of a picture through libtorch, kSegmentationClasses x h x w
  // channel-major (h, w: half the picture's), normalised as in training: what the exported model
  // must reproduce.
  std::function<std::vector<float>(const Image& rgb, int& h, int& w)> torch_logits;
  bool interrupted = false;
};

// Trains on `pictures` (all of config's input size). Throws std::invalid_argument on pictures of
// another size, no pictures, or a crop larger than the input.
SegTrainResult trainSegmentation(const std::vector<LabelledPicture>& pictures,
                                 const SegTrainConfig& config,
                                 const SegTrainCallbacks& callbacks = {});

}  // namespace semsegmap
