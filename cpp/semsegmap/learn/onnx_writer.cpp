#include "semsegmap/learn/onnx_writer.h"

#include <onnx/onnx_pb.h>

#include <stdexcept>

#include "semsegmap/core/atomic_file.h"

namespace semsegmap {

namespace {

constexpr int kOpset = 11;  // what OpenCV 4.6's ONNX importer reads

void addInts(onnx::NodeProto& node, const std::string& name, const std::vector<long long>& v) {
  onnx::AttributeProto* a = node.add_attribute();
  a->set_name(name);
  a->set_type(onnx::AttributeProto::INTS);
  for (long long x : v) a->add_ints(x);
}

void addString(onnx::NodeProto& node, const std::string& name, const std::string& value) {
  onnx::AttributeProto* a = node.add_attribute();
  a->set_name(name);
  a->set_type(onnx::AttributeProto::STRING);
  a->set_s(value);
}

void addInitializer(onnx::GraphProto& graph, const OnnxGraph::Tensor& t) {
  onnx::TensorProto* tensor = graph.add_initializer();
  tensor->set_name(t.name);
  tensor->set_data_type(onnx::TensorProto::FLOAT);
  for (long long d : t.shape) tensor->add_dims(d);
  for (float v : t.values) tensor->add_float_data(v);
}

// An N x channels x H x W float value with symbolic sizes.
void describeValue(onnx::ValueInfoProto& value, const std::string& name, int channels,
                   const std::string& h, const std::string& w) {
  value.set_name(name);
  onnx::TypeProto_Tensor* type = value.mutable_type()->mutable_tensor_type();
  type->set_elem_type(onnx::TensorProto::FLOAT);
  onnx::TensorShapeProto* shape = type->mutable_shape();
  shape->add_dim()->set_dim_value(1);
  shape->add_dim()->set_dim_value(channels);
  shape->add_dim()->set_dim_param(h);
  shape->add_dim()->set_dim_param(w);
}

void addNode(onnx::GraphProto& graph, const OnnxGraph::Node& n) {
  onnx::NodeProto* node = graph.add_node();
  node->set_op_type(n.op);
  node->set_name(n.output);
  for (const std::string& in : n.inputs) node->add_input(in);
  node->add_output(n.output);
  if (n.op == "Conv") {
    const OnnxConv& c = n.conv;
    const long long pad = static_cast<long long>(c.dilation) * (c.kernel - 1) / 2;
    addInts(*node, "kernel_shape", {c.kernel, c.kernel});
    addInts(*node, "strides", {c.stride, c.stride});
    addInts(*node, "dilations", {c.dilation, c.dilation});
    addInts(*node, "pads", {pad, pad, pad, pad});
  } else if (n.op == "Resize") {
    addString(*node, "mode", "linear");
    addString(*node, "coordinate_transformation_mode", "half_pixel");
  } else if (n.op == "Concat") {
    onnx::AttributeProto* a = node->add_attribute();
    a->set_name("axis");
    a->set_type(onnx::AttributeProto::INT);
    a->set_i(1);
  }
}

}  // namespace

OnnxGraph::OnnxGraph(int channels) : channels_(channels) {}

std::string OnnxGraph::next(const std::string& stem) {
  return stem + std::to_string(++counter_);
}

std::string OnnxGraph::constant(const std::string& stem, std::vector<long long> shape,
                                std::vector<float> values) {
  const std::string name = next(stem);
  constants_.push_back({name, std::move(shape), std::move(values)});
  return name;
}

std::string OnnxGraph::conv(const std::string& x, const OnnxConv& c) {
  const size_t weights = static_cast<size_t>(c.out_channels) * c.in_channels * c.kernel * c.kernel;
  if (c.weight.size() != weights || c.bias.size() != static_cast<size_t>(c.out_channels) ||
      c.in_channels < 1 || c.out_channels < 1 || c.kernel % 2 == 0 || c.stride < 1 ||
      c.dilation < 1)
    throw std::invalid_argument("ONNX conv: " + std::to_string(c.weight.size()) + " weights and " +
                                std::to_string(c.bias.size()) + " biases do not fit " +
                                std::to_string(c.out_channels) + "x" +
                                std::to_string(c.in_channels) + "x" + std::to_string(c.kernel) +
                                " (channels, stride and dilation >= 1, odd kernel)");
  const std::string w =
      constant("w", {c.out_channels, c.in_channels, c.kernel, c.kernel}, c.weight);
  const std::string b = constant("b", {c.out_channels}, c.bias);
  Node node{"Conv", {x, w, b}, next("conv"), c};
  node.conv.weight.clear();  // the initialisers hold them
  node.conv.bias.clear();
  nodes_.push_back(std::move(node));
  return nodes_.back().output;
}

std::string OnnxGraph::relu(const std::string& x) {
  nodes_.push_back({"Relu", {x}, next("relu"), {}});
  return nodes_.back().output;
}

std::string OnnxGraph::upsample2(const std::string& x) {
  const std::string roi = constant("roi", {0}, {});
  const std::string scales = constant("scales", {4}, {1.f, 1.f, 2.f, 2.f});
  nodes_.push_back({"Resize", {x, roi, scales}, next("resize"), {}});
  return nodes_.back().output;
}

std::string OnnxGraph::add(const std::string& a, const std::string& b) {
  nodes_.push_back({"Add", {a, b}, next("add"), {}});
  return nodes_.back().output;
}

std::string OnnxGraph::concat(const std::vector<std::string>& xs) {
  nodes_.push_back({"Concat", xs, next("concat"), {}});
  return nodes_.back().output;
}

std::string OnnxGraph::serialize(const std::string& output, int output_channels,
                                 const std::string& producer) const {
  onnx::ModelProto model;
  model.set_ir_version(6);  // the IR of opset 11
  model.set_producer_name(producer);
  onnx::OperatorSetIdProto* opset = model.add_opset_import();
  opset->set_domain("");
  opset->set_version(kOpset);
  onnx::GraphProto* graph = model.mutable_graph();
  graph->set_name(producer);
  for (const Tensor& t : constants_) addInitializer(*graph, t);
  for (const Node& n : nodes_) addNode(*graph, n);
  describeValue(*graph->add_input(), input_, channels_, "H", "W");
  describeValue(*graph->add_output(), output, output_channels, "h", "w");
  std::string bytes;
  if (!model.SerializeToString(&bytes)) throw std::runtime_error("ONNX model: cannot serialize");
  return bytes;
}

void OnnxGraph::write(const std::filesystem::path& path, const std::string& output,
                      int output_channels, const std::string& producer) const {
  writeBytesAtomically(path, serialize(output, output_channels, producer));
}

}  // namespace semsegmap
