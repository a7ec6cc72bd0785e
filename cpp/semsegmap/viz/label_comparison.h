// Pictures next to their true labels and a network's (`semsegmap eval labels`): one row per
// picture, picture | truth | network, the labels in the class table's colours, with a legend of
// the classes shown.
#pragma once

#include <string>
#include <vector>

#include "semsegmap/core/class_table.h"
#include "semsegmap/core/image.h"

namespace semsegmap::viz {

struct LabelComparison {
  std::string title;  // over the row's picture
  Image rgb, truth, predicted;
};

// Each row shrunk to at most `max_width` pixels (0: as they are). Throws std::invalid_argument
// when there are no rows.
Image drawLabelComparisons(const std::vector<LabelComparison>& rows, const ClassTable& classes,
                           int max_width = 1920);

}  // namespace semsegmap::viz
