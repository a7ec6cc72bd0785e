// PNG reading and writing for the plain Image type (OpenCV's codecs underneath).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "semsegmap/core/image.h"

namespace semsegmap {

// Reads an 8-bit PNG. RGB images come back as 3 channels in R, G, B order; single-channel
// images as 1 channel. Throws std::runtime_error naming the file when it is missing or corrupt.
Image readPng(const std::filesystem::path& path);
// Reads a camera picture, PNG or JPEG, as 3-channel RGB (a grey picture is repeated into the
// three channels, alpha dropped). Throws std::runtime_error naming the file when it is missing,
// corrupt or not 8-bit.
Image readColorImage(const std::filesystem::path& path);
// A PNG or JPEG held in memory (a file's bytes, a compressed ROS image) as 3-channel RGB, as
// readColorImage reads files. Throws std::runtime_error "<what>: ..." when it does not decode.
Image decodeColorImage(const uint8_t* data, size_t size, const std::string& what);
// Writes atomically (temporary name + rename). Throws naming the file on failure.
void writePng(const std::filesystem::path& path, const Image& image);

}  // namespace semsegmap
