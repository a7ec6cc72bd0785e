#include "semsegmap/io/ros_decode.h"

#include "semsegmap/core/shown_text.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/io/point_fields.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace semsegmap::rosmsg {
namespace {

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw std::runtime_error(shownText(where + ": " + what, std::string::npos));
}

void checkCloudSizes(const PointCloud2& msg, const std::string& where) {
  if (msg.is_bigendian)
    fail(where, "big-endian PointCloud2 is not supported (is_bigendian is set)");
  const uint64_t row_bytes = static_cast<uint64_t>(msg.width) * msg.point_step;
  if (msg.height > 0 && msg.row_step < row_bytes)
    fail(where, "row_step " + std::to_string(msg.row_step) + " is less than width * point_step " +
                    std::to_string(row_bytes));
  const uint64_t needed =
      msg.height == 0 ? 0 : static_cast<uint64_t>(msg.row_step) * (msg.height - 1) + row_bytes;
  if (msg.data.size() < needed)
    fail(where, "data holds " + std::to_string(msg.data.size()) + " bytes, but " +
                    std::to_string(msg.height) + " x " + std::to_string(msg.width) +
                    " points need " + std::to_string(needed));
}

}  // namespace

// The records are decoded by io/point_fields.h, row by row: a row may end in padding
// (row_step > width * point_step), which the shared decoder does not know about.
DecodedCloud decodePointCloud2(const PointCloud2& msg, const std::string& where) {
  checkCloudSizes(msg, where);
  std::vector<PointFieldSpec> fields;
  for (const PointField& f : msg.fields)
    fields.push_back({f.name, f.offset, static_cast<FieldType>(f.datatype), f.count});
  DecodedCloud out;
  // Rows of no points hold nothing: billions of them would be decoded one by one.
  if (msg.width == 0) return out;
  std::vector<double> times;
  for (uint32_t row = 0; row < msg.height; ++row) {
    const uint8_t* row_data = msg.data.data() + static_cast<size_t>(row) * msg.row_step;
    const size_t row_bytes = static_cast<size_t>(msg.width) * msg.point_step;
    DecodedPoints d =
        decodePointFields(fields, msg.point_step, row_data, row_bytes, msg.width, where);
    out.points.insert(out.points.end(), d.points.begin(), d.points.end());
    times.insert(times.end(), d.times.begin(), d.times.end());
    out.dropped_invalid += d.dropped_invalid;
    out.rings = std::max(out.rings, d.rings);
  }
  out.point_times = relativePointTimes(times, msg.header.stamp_s);
  return out;
}

namespace {

semsegmap::Image fromRgbMat(const cv::Mat& rgb) {
  semsegmap::Image out(rgb.cols, rgb.rows, 3);
  for (int y = 0; y < rgb.rows; ++y)
    std::memcpy(out.at(0, y), rgb.ptr<uint8_t>(y), static_cast<size_t>(rgb.cols) * 3);
  return out;
}

struct EncodingInfo {
  const char* name;
  int channels;
  int conversion;  // OpenCV colour conversion into RGB; -1: already RGB
};

// OpenCV names a Bayer pattern by the second row's second and third pixels, ROS by the first
// row's first two: ROS rggb is OpenCV's BG, and so on.
constexpr EncodingInfo kEncodings[] = {
    {"rgb8", 3, -1},
    {"bgr8", 3, cv::COLOR_BGR2RGB},
    {"rgba8", 4, cv::COLOR_RGBA2RGB},
    {"bgra8", 4, cv::COLOR_BGRA2RGB},
    {"mono8", 1, cv::COLOR_GRAY2RGB},
    {"8UC1", 1, cv::COLOR_GRAY2RGB},
    {"8UC3", 3, cv::COLOR_BGR2RGB},  // OpenCV's own order
    {"bayer_rggb8", 1, cv::COLOR_BayerBG2RGB},
    {"bayer_bggr8", 1, cv::COLOR_BayerRG2RGB},
    {"bayer_gbrg8", 1, cv::COLOR_BayerGR2RGB},
    {"bayer_grbg8", 1, cv::COLOR_BayerGB2RGB},
};

}  // namespace

semsegmap::Image decodeImage(const Image& msg, const std::string& where) {
  const EncodingInfo* enc = nullptr;
  for (const EncodingInfo& e : kEncodings)
    if (msg.encoding == e.name) enc = &e;
  if (!enc)
    fail(where, "image encoding '" + msg.encoding +
                    "' is not supported (rgb8, bgr8, rgba8, bgra8, mono8, bayer_rggb8, "
                    "bayer_bggr8, bayer_gbrg8, bayer_grbg8)");
  const uint64_t row_bytes = static_cast<uint64_t>(msg.width) * enc->channels;
  if (msg.width == 0 || msg.height == 0) fail(where, "image has size 0");
  if (msg.step < row_bytes || static_cast<uint64_t>(msg.step) * msg.height > msg.data.size())
    fail(where, "image " + std::to_string(msg.width) + "x" + std::to_string(msg.height) + " " +
                    msg.encoding + " does not fit step " + std::to_string(msg.step) + " and " +
                    std::to_string(msg.data.size()) + " bytes of data");
  const cv::Mat raw(static_cast<int>(msg.height), static_cast<int>(msg.width),
                    CV_8UC(enc->channels), const_cast<uint8_t*>(msg.data.data()), msg.step);
  if (enc->conversion < 0) return fromRgbMat(raw);
  cv::Mat rgb;
  cv::cvtColor(raw, rgb, enc->conversion);
  return fromRgbMat(rgb);
}

semsegmap::Image decodeCompressedImage(const CompressedImage& msg, const std::string& where) {
  return decodeColorImage(msg.data.data(), msg.data.size(),
                          where + ": compressed image (format '" + shownText(msg.format) + "')");
}

namespace {

bool allZero(const std::vector<double>& d, size_t from) {
  for (size_t i = from; i < d.size(); ++i)
    if (d[i] != 0.0) return false;
  return true;
}

// The coefficients of the camera's lens model, or a refusal naming what does not fit.
void setLensModel(Camera& cam, const CameraInfo& msg, const std::string& where) {
  const std::string& model = msg.distortion_model;
  const std::vector<double>& D = msg.D;
  auto take = [&](size_t n) {
    for (size_t i = 0; i < std::min(n, D.size()); ++i) cam.distortion[i] = D[i];
  };
  if (model == "plumb_bob" || model == "rational_polynomial") {
    const size_t limit = model == "plumb_bob" ? 5 : 8;
    if (D.size() > limit)
      fail(where, model + " with " + std::to_string(D.size()) + " coefficients");
    if (!allZero(D, 5))
      fail(where,
           "rational_polynomial with non-zero k4 k5 k6 is not supported (only its first "
           "five coefficients, the plumb_bob model)");
    take(5);
    cam.model = allZero(D, 0) ? CameraModel::kPinhole : CameraModel::kRadialTangential;
  } else if (model == "equidistant") {
    if (D.size() != 4)
      fail(where, "equidistant needs 4 coefficients k1..k4, got " + std::to_string(D.size()));
    take(4);
    cam.model = CameraModel::kEquidistant;
  } else if ((model.empty() || model == "none") && allZero(D, 0)) {
    cam.model = CameraModel::kPinhole;
  } else {
    fail(where, "distortion_model '" + model +
                    "' is not supported (plumb_bob, rational_polynomial, equidistant)");
  }
}

}  // namespace

Camera cameraFromInfo(const CameraInfo& msg, const std::string& where) {
  if (msg.width == 0 || msg.height == 0)
    fail(where, "CameraInfo has no image size (width, height)");
  if (msg.width > kMaxCameraSide || msg.height > kMaxCameraSide)
    fail(where, "CameraInfo image size " + std::to_string(msg.width) + "x" +
                    std::to_string(msg.height) + " is beyond " + std::to_string(kMaxCameraSide));
  const auto finite = [](double v) { return std::isfinite(v); };
  if (!std::all_of(msg.K.begin(), msg.K.end(), finite) ||
      !std::all_of(msg.D.begin(), msg.D.end(), finite))
    fail(where, "CameraInfo K or D holds a NaN or infinite value");
  Camera cam;
  cam.width = static_cast<int>(msg.width);
  cam.height = static_cast<int>(msg.height);
  cam.fx = msg.K[0];
  cam.fy = msg.K[4];
  cam.cx = msg.K[2];
  cam.cy = msg.K[5];
  if (!(cam.fx > 0 && cam.fy > 0))
    fail(where, "CameraInfo K has no positive focal lengths (an uncalibrated camera)");
  if (std::abs(msg.K[1]) > 1e-9 * cam.fx)
    fail(where, "CameraInfo K has a skew term, which the camera model does not have");
  setLensModel(cam, msg, where);
  return cam;
}

Pose poseOf(const Transform& t) {
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(t.translation[0], t.translation[1], t.translation[2]);
  Eigen::Quaterniond q(t.rotation[3], t.rotation[0], t.rotation[1], t.rotation[2]);
  if (!q.coeffs().allFinite() || !(q.norm() > 1e-6) || !T.translation().allFinite())
    throw std::invalid_argument("transform with a zero or non-finite quaternion or translation");
  T.linear() = q.normalized().toRotationMatrix();  // recorded quaternions are rounded
  return T;
}

StampedPose stampedPoseOf(const Odometry& msg) {
  return StampedPose{msg.header.stamp_s, poseOf(msg.pose)};
}

LidarModel lidarModelOf(const PointCloud2& msg, const DecodedCloud& cloud) {
  LidarModel m;
  m.rows = cloud.rings > 0 ? cloud.rings : msg.height > 1 ? static_cast<int>(msg.height) : 64;
  m.columns = msg.height > 1 ? static_cast<int>(msg.width)
                             : std::max<int>(1, static_cast<int>(cloud.points.size()) / m.rows);
  m.hfov_deg = 360.0;
  m.range_noise_m = 0.0;
  m.dropout = 0.0;
  m.min_range_m = 0.0;
  double up = -90, down = 90, far = 0;
  for (const LidarPoint& p : cloud.points) {
    const double flat = std::hypot(p.x, p.y), range = std::hypot(flat, p.z);
    if (range <= 0) continue;
    const double elevation = std::atan2(p.z, flat) * 180.0 / M_PI;
    up = std::max(up, elevation);
    down = std::min(down, elevation);
    far = std::max(far, range);
  }
  if (up > down) {
    m.vfov_up_deg = up;
    m.vfov_down_deg = down;
  }
  m.max_range_m = far > 1.0 ? far * 1.01 : 100.0;
  return m;
}

}  // namespace semsegmap::rosmsg
