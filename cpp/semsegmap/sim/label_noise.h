// Imperfect semantics in the simulator: the perfect label images degraded the way a real
// segmentation network is wrong, so that what the semantic distance and the descriptors gain
// from classes can be measured against how good the network is. Four levels (README, "Imperfect
// semantics"):
//   0  perfect labels
//   1  a good Cityscapes model: boundaries off by up to 2 px, 5 % of the confusable area
//      confused (fence/building/vegetation, terrain/sidewalk), 20 % of thin objects missed
//   2  a mediocre one: 4 px, 12 %, 40 %, and 3 % of the picture one wrong class
//   3  worse than a good Cityscapes model: 8 px, 25 %, 60 %, 8 %
// Every effect is a smooth random field over the picture (blobs and wavy boundaries, not pixel
// salt), a pure function of the seed: the same frame gets the same errors on every run.
#pragma once

#include <cstdint>

#include "semsegmap/core/image.h"

namespace semsegmap::sim {

struct LabelNoise {
  double boundary_px = 0;   // largest shift of a class boundary
  double confusion = 0;     // share of the confusable classes' area given the partner class
  double thin_missed = 0;   // share of poles, signs and trunks labelled as their background
  double wrong_region = 0;  // share of the picture labelled as one wrong class
};

constexpr int kMaxLabelNoiseLevel = 3;
// Throws std::invalid_argument for a level outside 0..kMaxLabelNoiseLevel.
LabelNoise labelNoiseOfLevel(int level);

// The label image (the default class table's ids) with the errors of `noise`.
Image applyLabelNoise(const Image& labels, const LabelNoise& noise, uint64_t seed);

}  // namespace semsegmap::sim
