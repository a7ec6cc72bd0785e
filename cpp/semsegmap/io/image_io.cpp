#include "semsegmap/io/image_io.h"

#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "semsegmap/core/atomic_file.h"

namespace semsegmap {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& what) {
  throw std::runtime_error(path.string() + ": " + what);
}

Image fromMat(const cv::Mat& m) {
  Image image(m.cols, m.rows, m.channels());
  const size_t row_bytes = static_cast<size_t>(m.cols) * m.channels();
  // Row by row because a decoded Mat need not be continuous.
  for (int y = 0; y < m.rows; ++y) std::memcpy(image.at(0, y), m.ptr<uint8_t>(y), row_bytes);
  return image;
}

}  // namespace

Image readPng(const std::filesystem::path& path) {
  const std::string bytes = readFileBytes(path);
  // OpenCV would happily decode a JPEG named .png; the format promises PNG, so check.
  static const char kSignature[] = "\x89PNG\r\n\x1a\n";
  if (bytes.size() < 8 || bytes.compare(0, 8, kSignature, 8) != 0) fail(path, "not a PNG file");

  cv::Mat decoded;
  try {
    // imdecode rather than imread: the bytes are already read, so a missing file and a corrupt
    // one give different messages, and IMREAD_UNCHANGED keeps label images single-channel.
    const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data()));
    decoded = cv::imdecode(buffer, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    fail(path, "corrupt PNG (" + e.err + ")");
  }
  if (decoded.empty()) fail(path, "corrupt PNG (cannot decode)");
  if (decoded.depth() != CV_8U)
    fail(path, "PNG has " + std::to_string(8 * decoded.elemSize1()) +
                   "-bit samples, only 8-bit images are supported");

  cv::Mat rgb;
  switch (decoded.channels()) {
    case 1:
      return fromMat(decoded);
    case 3:
      cv::cvtColor(decoded, rgb, cv::COLOR_BGR2RGB);
      return fromMat(rgb);
    case 4:
      // Alpha carries nothing the pipeline uses; dropping it lets RGBA exports read as RGB.
      cv::cvtColor(decoded, rgb, cv::COLOR_BGRA2RGB);
      return fromMat(rgb);
    default:
      fail(path, "PNG has " + std::to_string(decoded.channels()) + " channels, expected 1, 3 or 4");
  }
}

Image decodeColorImage(const uint8_t* data, size_t size, const std::string& what) {
  cv::Mat decoded;
  try {
    if (size > 0) {
      const cv::Mat buffer(1, static_cast<int>(size), CV_8U, const_cast<uint8_t*>(data));
      decoded = cv::imdecode(buffer, cv::IMREAD_COLOR);  // BGR, 8 bit, grey expanded
    }
  } catch (const cv::Exception& e) {
    throw std::runtime_error(what + ": corrupt image (" + e.err + ")");
  }
  if (decoded.empty())
    throw std::runtime_error(what + ": not a readable PNG or JPEG image (" + std::to_string(size) +
                             " bytes)");
  cv::Mat rgb;
  cv::cvtColor(decoded, rgb, cv::COLOR_BGR2RGB);
  return fromMat(rgb);
}

Image readColorImage(const std::filesystem::path& path) {
  const std::string bytes = readFileBytes(path);
  return decodeColorImage(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(),
                          path.string());
}

void writePng(const std::filesystem::path& path, const Image& image) {
  if (image.channels != 1 && image.channels != 3)
    throw std::invalid_argument(path.string() + ": image has " + std::to_string(image.channels) +
                                " channels, expected 1 (labels) or 3 (RGB)");
  if (image.width <= 0 || image.height <= 0 ||
      image.data.size() != static_cast<size_t>(image.width) * image.height * image.channels)
    throw std::invalid_argument(path.string() + ": image is " + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + "x" +
                                std::to_string(image.channels) + " but holds " +
                                std::to_string(image.data.size()) + " bytes");

  // OpenCV only reads through this header; the const_cast never leads to a write.
  const cv::Mat view(image.height, image.width, CV_8UC(image.channels),
                     const_cast<uint8_t*>(image.data.data()));
  // A fresh Mat for the conversion: cvtColor into a header sharing `view` would convert in place,
  // i.e. write into the caller's const image.
  cv::Mat to_encode;
  if (image.channels == 3)
    cv::cvtColor(view, to_encode, cv::COLOR_RGB2BGR);
  else
    to_encode = view;

  std::vector<uint8_t> encoded;
  try {
    if (!cv::imencode(".png", to_encode, encoded)) fail(path, "PNG encoding failed");
  } catch (const cv::Exception& e) {
    fail(path, "PNG encoding failed (" + e.err + ")");
  }
  writeBytesAtomically(path, std::string(encoded.begin(), encoded.end()));
}

}  // namespace semsegmap
