// A small ONNX graph of the operators OpenCV 4.6's importer reads at opset 11 (Conv, Relu,
// Resize, Add, Concat), written from plain float arrays: the project's segmentation network is
// trained with libtorch and exported with this, so that the semantics stage runs it through
// OpenCV's DNN module like any other network. No libtorch or ONNX types in this header.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace semsegmap {

// A 2-D convolution with square kernels, "same" padding (dilation * (kernel - 1) / 2).
struct OnnxConv {
  int in_channels = 0, out_channels = 0, kernel = 1, stride = 1, dilation = 1;
  std::vector<float> weight;  // out x in x kernel x kernel, row-major (torch's layout)
  std::vector<float> bias;    // out
};

class OnnxGraph {
 public:
  // The graph's input: `channels` x H x W float, named "image", any H and W.
  explicit OnnxGraph(int channels = 3);

  const std::string& input() const { return input_; }
  // Each returns the name of the node's output. Throws std::invalid_argument on weights whose
  // size does not match the shape.
  std::string conv(const std::string& x, const OnnxConv& c);
  std::string relu(const std::string& x);
  std::string upsample2(const std::string& x);  // bilinear, half-pixel centres (torch's default)
  std::string add(const std::string& a, const std::string& b);
  std::string concat(const std::vector<std::string>& xs);  // along the channels

  // The model's bytes with `output` (channels x h x w) as the graph's output.
  std::string serialize(const std::string& output, int output_channels,
                        const std::string& producer) const;
  // Written to a temporary name and renamed (core/atomic_file.h).
  void write(const std::filesystem::path& path, const std::string& output, int output_channels,
             const std::string& producer) const;

  struct Node {
    std::string op;
    std::vector<std::string> inputs;
    std::string output;
    OnnxConv conv;  // for Conv
  };
  struct Tensor {
    std::string name;
    std::vector<long long> shape;
    std::vector<float> values;
  };

 private:
  std::string next(const std::string& stem);
  std::string constant(const std::string& stem, std::vector<long long> shape,
                       std::vector<float> values);

  std::string input_ = "image";
  int channels_;
  int counter_ = 0;
  std::vector<Node> nodes_;
  std::vector<Tensor> constants_;
};

}  // namespace semsegmap
