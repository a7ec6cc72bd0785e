// A label image over its picture, to see what a segmentation network (or a label set) says: the
// picture on the left, the labels blended over it on the right, the classes present listed with
// their colours and shares.
#pragma once

#include <string>

#include "semsegmap/core/class_table.h"
#include "semsegmap/core/image.h"

namespace semsegmap::viz {

// `title` goes over the picture; max_width > 0 shrinks the result to at most that width.
Image drawLabelOverlay(const Image& rgb, const Image& labels, const ClassTable& classes,
                       const std::string& title, int max_width = 0);

}  // namespace semsegmap::viz
