// A plain 8-bit image (row-major, interleaved channels) so that core and the stages need no
// imaging library; io/ converts to and from PNG.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace semsegmap {

struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;  // 3 for RGB, 1 for class labels
  std::vector<uint8_t> data;

  Image() = default;
  Image(int w, int h, int c, uint8_t fill = 0)
      : width(w), height(h), channels(c), data(static_cast<size_t>(w) * h * c, fill) {}

  bool empty() const { return data.empty(); }
  uint8_t* at(int x, int y) { return &data[(static_cast<size_t>(y) * width + x) * channels]; }
  const uint8_t* at(int x, int y) const {
    return &data[(static_cast<size_t>(y) * width + x) * channels];
  }
  bool operator==(const Image& o) const {
    return width == o.width && height == o.height && channels == o.channels && data == o.data;
  }
};

}  // namespace semsegmap
