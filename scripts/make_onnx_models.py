#!/usr/bin/python3
"""Writes the small ONNX segmentation networks the tests and the benchmark run.

No pretrained network can be shipped or downloaded, so the semantics stage is tested on networks
whose behaviour is known by construction, and benchmarked on one of realistic size with seeded
random weights. Built with Debian's python3-onnx (onnx.helper), no deep-learning framework:

  colour4.onnx          1x1 convolution, 4 classes: 0 red, 1 green, 2 blue (the largest of the
                        three normalised channels), 3 dark (a constant logit of 0.25 beats them
                        all when every channel is below it); logits NCHW at the input's size
  colour4_argmax.onnx   the same followed by ArgMax over the classes: an argmax map N1HW
  colour4_half.onnx     2x2 average pooling first: logits at half the input's size
  fixed_input.onnx      the 1x1 convolution, flattened through a 256x256 fully connected layer
                        and reshaped to 1x4x8x8: refuses every other input size
  mobilenet_seg.onnx    a MobileNet-v1 encoder (depthwise-separable blocks down to 1/16) and a
                        decoder that upsamples to 1/8 and adds a skip connection: 19 classes
                        (Cityscapes' training classes), logits at 1/8 of the input

Usage: make_onnx_models.py OUT_DIR
"""
import os
import sys

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

OPSET = 11  # what OpenCV 4.6's importer reads


class Graph:
    def __init__(self, seed=0):
        self.nodes, self.inits, self.rng, self.n = [], [], np.random.default_rng(seed), 0

    def name(self, stem):
        self.n += 1
        return f"{stem}{self.n}"

    def const(self, array, stem="w"):
        name = self.name(stem)
        self.inits.append(numpy_helper.from_array(np.asarray(array), name))
        return name

    def node(self, op, inputs, stem=None, **attrs):
        out = self.name(stem or op.lower())
        self.nodes.append(helper.make_node(op, inputs, [out], **attrs))
        return out

    def conv(self, x, w, b, stride=1, group=1):
        k = w.shape[-1]
        return self.node("Conv", [x, self.const(w.astype(np.float32)),
                                  self.const(b.astype(np.float32), "b")],
                         strides=[stride, stride], pads=[k // 2] * 4, group=group,
                         kernel_shape=[k, k])

    def random_conv(self, x, c_in, c_out, k=1, stride=1, group=1):
        # He initialisation keeps the activations of a deep random stack in range.
        fan_in = c_in // group * k * k
        w = self.rng.normal(0, np.sqrt(2.0 / fan_in), (c_out, c_in // group, k, k))
        return self.node("Relu", [self.conv(x, w, np.zeros(c_out), stride, group)])

    def save(self, path, output, output_shape, output_type=TensorProto.FLOAT):
        image = helper.make_tensor_value_info("image", TensorProto.FLOAT, [1, 3, "H", "W"])
        out = helper.make_tensor_value_info(output, output_type, output_shape)
        graph = helper.make_graph(self.nodes, os.path.basename(path), [image], [out], self.inits)
        model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", OPSET)],
                                  producer_name="semsegmap make_onnx_models.py")
        onnx.checker.check_model(model)
        onnx.save(model, path)


def colour_logits(g, x):
    w = np.zeros((4, 3, 1, 1))
    for c in range(3):
        w[c, c, 0, 0] = 1.0
    return g.conv(x, w, np.array([0.0, 0.0, 0.0, 0.25]))


def colour4(out):
    g = Graph()
    g.save(os.path.join(out, "colour4.onnx"), colour_logits(g, "image"), [1, 4, "H", "W"])
    g = Graph()
    am = g.node("ArgMax", [colour_logits(g, "image")], axis=1, keepdims=1)
    g.save(os.path.join(out, "colour4_argmax.onnx"), am, [1, 1, "H", "W"], TensorProto.INT64)
    g = Graph()
    pooled = g.node("AveragePool", ["image"], kernel_shape=[2, 2], strides=[2, 2])
    g.save(os.path.join(out, "colour4_half.onnx"), colour_logits(g, pooled), [1, 4, "h", "w"])
    g = Graph()
    # A fully connected layer over the flattened 4x8x8 logits (identity weights) fixes the size.
    flat = g.node("Flatten", [colour_logits(g, "image")], axis=1)
    dense = g.node("Gemm", [flat, g.const(np.eye(256, dtype=np.float32))])
    fixed = g.node("Reshape", [dense, g.const(np.array([1, 4, 8, 8]), "s")])
    g.save(os.path.join(out, "fixed_input.onnx"), fixed, [1, 4, 8, 8])


def mobilenet_seg(out, classes=19):
    g = Graph(seed=7)
    x = g.random_conv("image", 3, 32, k=3, stride=2)  # 1/2
    # MobileNet-v1's depthwise-separable blocks: (output channels, stride)
    blocks = [(64, 1), (128, 2), (128, 1), (256, 2), (256, 1), (512, 2)] + [(512, 1)] * 5
    c, skip = 32, None
    for c_out, stride in blocks:
        if stride == 2 and c == 256:
            skip = x  # the 1/8 features
        x = g.random_conv(x, c, c, k=3, stride=stride, group=c)  # depthwise
        x = g.random_conv(x, c, c_out)  # pointwise
        c = c_out
    coarse = g.conv(x, g.rng.normal(0, 0.05, (classes, 512, 1, 1)), np.zeros(classes))  # 1/16
    up = g.node("Resize", [coarse, g.const(np.array([], np.float32), "roi"),
                           g.const(np.array([1, 1, 2, 2], np.float32), "scales")],
                mode="linear", coordinate_transformation_mode="half_pixel")
    fine = g.conv(skip, g.rng.normal(0, 0.05, (classes, 256, 1, 1)), np.zeros(classes))
    g.save(os.path.join(out, "mobilenet_seg.onnx"), g.node("Add", [up, fine]),
           [1, classes, "h", "w"])


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    os.makedirs(sys.argv[1], exist_ok=True)
    colour4(sys.argv[1])
    mobilenet_seg(sys.argv[1])


if __name__ == "__main__":
    main()
