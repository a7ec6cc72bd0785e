// PNG reading and writing for the plain Image type (OpenCV's codecs underneath).
#pragma once

#include <filesystem>

#include "semsegmap/core/image.h"

namespace semsegmap {

// Reads an 8-bit PNG. RGB images come back as 3 channels in R, G, B order; single-channel
// images as 1 channel. Throws std::runtime_error naming the file when it is missing or corrupt.
Image readPng(const std::filesystem::path& path);
// Writes atomically (temporary name + rename). Throws naming the file on failure.
void writePng(const std::filesystem::path& path, const Image& image);

}  // namespace semsegmap
