#include "semsegmap/enrich/enricher.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

namespace semsegmap {

namespace {

std::string sizeText(const Image& im) {
  return std::to_string(im.width) + "x" + std::to_string(im.height) + "x" +
         std::to_string(im.channels);
}

// An image of the frame must be empty (that camera gives no colour / no class) or exactly the
// camera's size with the expected channels; anything else is a mismatched rig and frame.
void checkImage(const Frame& frame, const Camera& cam, const Image& im, int channels,
                const char* what) {
  if (im.empty()) return;
  const bool ok = im.width == cam.width && im.height == cam.height && im.channels == channels &&
                  im.data.size() == static_cast<size_t>(cam.width) * cam.height * channels;
  if (!ok)
    throw std::invalid_argument("frame " + std::to_string(frame.index) + ": camera '" + cam.name +
                                "': " + what + " image is " + sizeText(im) + ", expected " +
                                std::to_string(cam.width) + "x" + std::to_string(cam.height) + "x" +
                                std::to_string(channels));
}

void checkInputs(const Frame& frame, const SensorRig& rig) {
  const std::string where = "frame " + std::to_string(frame.index) + ": ";
  if (!frame.cameras.empty() && frame.cameras.size() != rig.cameras.size()) {
    std::string names;
    for (const auto& c : rig.cameras) names += (names.empty() ? "'" : ", '") + c.name + "'";
    throw std::invalid_argument(where + std::to_string(frame.cameras.size()) +
                                " camera images but the rig has " +
                                std::to_string(rig.cameras.size()) + " cameras (" + names + ")");
  }
  for (size_t c = 0; c < frame.cameras.size(); ++c) {
    const Camera& cam = rig.cameras[c];
    // Its z-buffer is allocated whole (SensorRig::validate has the same limit).
    if (cam.width <= 0 || cam.height <= 0 || cam.width > kMaxCameraSide ||
        cam.height > kMaxCameraSide)
      throw std::invalid_argument(where + "camera '" + cam.name + "': size " +
                                  std::to_string(cam.width) + "x" + std::to_string(cam.height) +
                                  " is outside 1.." + std::to_string(kMaxCameraSide));
    checkImage(frame, cam, frame.cameras[c].rgb, 3, "rgb");
    checkImage(frame, cam, frame.cameras[c].label, 1, "label");
  }
  if (!frame.point_labels.empty() && frame.point_labels.size() != frame.points.size())
    throw std::invalid_argument(where + std::to_string(frame.point_labels.size()) +
                                " point labels for " + std::to_string(frame.points.size()) +
                                " points");
  // Corrupt input must not pass silently: a NaN would otherwise project nowhere and vanish.
  for (size_t i = 0; i < frame.points.size(); ++i) {
    const LidarPoint& p = frame.points[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw std::invalid_argument(where + "point " + std::to_string(i) +
                                  " has a non-finite coordinate (" + std::to_string(p.x) + ", " +
                                  std::to_string(p.y) + ", " + std::to_string(p.z) + ")");
  }
}

// One point seen by one camera. Each point is also projected from the LiDAR's origin with the
// camera's orientation: the difference between the two is the camera/LiDAR parallax, the only
// thing that lets a camera be blocked where the LiDAR saw through.
struct Projection {
  int32_t pixel;  // row-major index of the pixel containing (u, v), or -1 when not in the image;
                  // the other fields are only set when it is
  float u, v;     // camera pixel coordinates
  float ul, vl;   // as seen from the LiDAR's origin; NaN when behind that viewpoint
  float depth;    // z in the camera frame
};

struct CameraView {
  std::vector<Projection> points;    // in frame order
  std::vector<int32_t> nearest;      // z-buffer: per pixel, the nearest point projected there or -1
  std::vector<float> nearest_depth;  // its depth (infinity when none), read first as it is dense
};

// Scratch reused from frame to frame by each calling thread: allocating and first touching
// ~10 MB per frame costs as much as the projection itself.
std::vector<CameraView>& scratchViews() {
  static thread_local std::vector<CameraView> views;
  return views;
}

// How far (pixels) the parallax must have moved a nearer point towards a point before the nearer
// one is taken to block the camera's view of it. Without this, a surface seen at a grazing angle
// hides itself: on a road 30 m away (simulated rig) two LiDAR rings are 2 pixels but 3 metres
// apart, and the nearer ring would "occlude" the farther one although the camera sees the road
// just as the LiDAR does.
constexpr float kMinParallaxShiftPx = 1.0f;

// The z-buffer test: a nearer point within `r` pixels (the neighbourhood fills the gaps between
// the sparse LiDAR points of an occluder) that is nearer by more than the tolerance and that the
// parallax moved towards this point, so that the camera sees it over this point's pixel.
bool occluded(const CameraView& view, const Camera& cam, size_t i, const EnrichmentConfig& config) {
  const Projection& p = view.points[i];
  const float nearer_than = p.depth - static_cast<float>(config.occlusion_tolerance_m +
                                                         config.occlusion_tolerance_rel * p.depth);
  const int r = config.occlusion_radius_px;
  const int x = p.pixel % cam.width, y = p.pixel / cam.width;
  const int x0 = std::max(0, x - r), x1 = std::min(cam.width - 1, x + r);
  const int y0 = std::max(0, y - r), y1 = std::min(cam.height - 1, y + r);
  for (int yy = y0; yy <= y1; ++yy) {
    const size_t row = static_cast<size_t>(yy) * cam.width;
    for (int xx = x0; xx <= x1; ++xx) {
      if (view.nearest_depth[row + xx] >= nearer_than) continue;  // also when no point is there
      const Projection& q = view.points[view.nearest[row + xx]];
      // Seen from the LiDAR's origin one of them is behind: the parallax is huge.
      if (std::isnan(q.ul) || std::isnan(p.ul)) return true;
      const float apart_camera = std::hypot(q.u - p.u, q.v - p.v);
      const float apart_lidar = std::hypot(q.ul - p.ul, q.vl - p.vl);
      if (apart_lidar - apart_camera >= kMinParallaxShiftPx) return true;
    }
  }
  return false;
}

}  // namespace

void rgbToHsv(uint8_t r, uint8_t g, uint8_t b, float& h, float& s, float& v) {
  const int mx = std::max({r, g, b}), mn = std::min({r, g, b});
  const int delta = mx - mn;
  v = mx / 255.0f;
  s = mx > 0 ? static_cast<float>(delta) / mx : 0.0f;
  if (delta == 0) {
    h = 0.0f;  // grey: hue undefined, 0 by convention
    return;
  }
  float sector;  // hue in sixths of the circle, in [-1, 5)
  if (mx == r)
    sector = static_cast<float>(g - b) / delta;
  else if (mx == g)
    sector = 2.0f + static_cast<float>(b - r) / delta;
  else
    sector = 4.0f + static_cast<float>(r - g) / delta;
  h = sector / 6.0f;
  if (h < 0.0f) h += 1.0f;
  // Hue is cyclic: a value that rounds up to 1 is the same colour as 0.
  if (h >= 1.0f) h = 0.0f;
}

namespace {

// Pass 1: every point into every camera (each camera's own extrinsics).
void projectPoints(const Frame& frame, const SensorRig& rig, std::vector<CameraView>& views) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  const auto n = static_cast<std::ptrdiff_t>(frame.points.size());
  const size_t n_cams = frame.cameras.size();
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const LidarPoint& lp = frame.points[i];
    const Eigen::Vector3d p(lp.x, lp.y, lp.z);
    for (size_t c = 0; c < n_cams; ++c) {
      const Camera& cam = rig.cameras[c];
      Projection& pr = views[c].points[i];
      const Eigen::Vector3d pc = cam.T_camera_lidar * p;
      const auto uv = cam.project(pc);
      pr.pixel = -1;
      if (!uv || !cam.inImage(*uv)) continue;
      // The pixel containing (u, v): pixel x covers [x, x + 1), the convention of inImage().
      pr.pixel = static_cast<int32_t>(uv->y()) * cam.width + static_cast<int32_t>(uv->x());
      pr.u = static_cast<float>(uv->x());
      pr.v = static_cast<float>(uv->y());
      pr.depth = static_cast<float>(pc.z());
      const auto uvl = cam.project(cam.T_camera_lidar.linear() * p);
      pr.ul = uvl ? static_cast<float>(uvl->x()) : kNaN;
      pr.vl = uvl ? static_cast<float>(uvl->y()) : kNaN;
    }
  }
}

// Z-buffers: the nearest point per pixel, one camera per thread. They are allocated here, before
// the parallel loop: an allocation that fails inside an OpenMP region cannot be caught and
// aborts the process, while here it is an exception the caller sees.
void fillZBuffers(const SensorRig& rig, size_t n_points, std::vector<CameraView>& views,
                  size_t n_cams) {
  for (size_t c = 0; c < n_cams; ++c) {
    const size_t pixels = static_cast<size_t>(rig.cameras[c].width) * rig.cameras[c].height;
    views[c].nearest.assign(pixels, -1);
    views[c].nearest_depth.assign(pixels, std::numeric_limits<float>::infinity());
  }
  const auto n = static_cast<std::ptrdiff_t>(n_points);
#pragma omp parallel for schedule(dynamic, 1)
  for (std::ptrdiff_t c = 0; c < static_cast<std::ptrdiff_t>(n_cams); ++c) {
    CameraView& view = views[c];
    for (std::ptrdiff_t i = 0; i < n; ++i) {
      const Projection& pr = view.points[i];
      if (pr.pixel < 0 || !(pr.depth < view.nearest_depth[pr.pixel])) continue;
      view.nearest[pr.pixel] = static_cast<int32_t>(i);
      view.nearest_depth[pr.pixel] = pr.depth;
    }
  }
}

// The unoccluded camera whose image centre is nearest to point i, and its pixel; -1 for none.
int bestCamera(const Frame& frame, const SensorRig& rig, const std::vector<CameraView>& views,
               size_t i, const EnrichmentConfig& config, size_t& best_pixel) {
  int best_cam = -1;
  double best_centre_dist = std::numeric_limits<double>::infinity();
  for (size_t c = 0; c < frame.cameras.size(); ++c) {
    const Projection& pr = views[c].points[i];
    if (pr.pixel < 0) continue;
    const CameraFrame& cf = frame.cameras[c];
    if (cf.rgb.empty() && cf.label.empty()) continue;  // this camera has nothing to give
    const Camera& cam = rig.cameras[c];
    if (occluded(views[c], cam, i, config)) continue;
    // Distance to the image centre, relative to the half diagonal, so that cameras of
    // different sizes compare fairly; lens effects are smallest near the centre.
    const double du = pr.u - 0.5 * cam.width, dv = pr.v - 0.5 * cam.height;
    const double d = (du * du + dv * dv) / (0.25 * (static_cast<double>(cam.width) * cam.width +
                                                    static_cast<double>(cam.height) * cam.height));
    if (d < best_centre_dist) {
      best_centre_dist = d;
      best_cam = static_cast<int>(c);
      best_pixel = static_cast<size_t>(pr.pixel);
    }
  }
  return best_cam;
}

// The class camera `cf` gives a point at `pixel`: read there, or, for labels of an earlier
// picture, where the point was then (the static world seen from the LiDAR's earlier pose);
// nothing when that picture did not see it.
std::optional<ClassId> cameraClass(const CameraFrame& cf, const Camera& cam, const LidarPoint& lp,
                                   size_t pixel) {
  if (!cf.T_label_lidar) return cf.label.data[pixel];
  const Eigen::Vector3d then = *cf.T_label_lidar * Eigen::Vector3d(lp.x, lp.y, lp.z);
  const auto uv = cam.project(cam.T_camera_lidar * then);
  if (!uv || !cam.inImage(*uv)) return std::nullopt;
  return cf.label.data[static_cast<size_t>(uv->y()) * cam.width + static_cast<size_t>(uv->x())];
}

}  // namespace

EnrichedCloud enrichFrame(const Frame& frame, const SensorRig& rig,
                          const EnrichmentConfig& config) {
  checkInputs(frame, rig);
  if (config.occlusion_radius_px < 0)
    throw std::invalid_argument("enrichment: occlusion_radius_px must not be negative, got " +
                                std::to_string(config.occlusion_radius_px));
  const auto n = static_cast<std::ptrdiff_t>(frame.points.size());
  const size_t n_cams = frame.cameras.size();  // 0 when the frame has no images at all
  bool camera_semantics = frame.camera_semantics;
  for (const auto& cf : frame.cameras) camera_semantics |= !cf.label.empty();
  // Point labels give classes only when some point has one: the simulator's point labels may
  // carry ground-truth instances alone, and those points are unobserved, not of class unknown.
  const bool point_semantics =
      !camera_semantics &&
      std::any_of(frame.point_labels.begin(), frame.point_labels.end(),
                  [](const PointLabel& l) { return l.class_id != cls::kUnknown; });

  std::vector<CameraView>& views = scratchViews();
  if (views.size() < n_cams) views.resize(n_cams);
  for (size_t c = 0; c < n_cams; ++c) views[c].points.resize(frame.points.size());
  projectPoints(frame, rig, views);
  fillZBuffers(rig, frame.points.size(), views, n_cams);

  // Pass 2: per point, the best camera gives colour and class.
  EnrichedCloud cloud(frame.points.size());
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const LidarPoint& lp = frame.points[i];
    EnrichedPoint& ep = cloud[i];
    ep.x = lp.x;
    ep.y = lp.y;
    ep.z = lp.z;
    if (!frame.point_labels.empty()) {
      ep.instance_id = frame.point_labels[i].instance_id;
      if (point_semantics) {
        ep.class_id = frame.point_labels[i].class_id;
        ep.has_class = true;
      }
    }
    size_t pixel = 0;
    const int cam = bestCamera(frame, rig, views, static_cast<size_t>(i), config, pixel);
    if (cam < 0) continue;
    const CameraFrame& cf = frame.cameras[cam];
    if (!cf.rgb.empty()) {
      const uint8_t* rgb = cf.rgb.data.data() + pixel * 3;
      rgbToHsv(rgb[0], rgb[1], rgb[2], ep.h, ep.s, ep.v);
      ep.has_color = true;
    }
    if (camera_semantics && !cf.label.empty()) {
      const std::optional<ClassId> c = cameraClass(cf, rig.cameras[cam], lp, pixel);
      ep.has_class = c.has_value();
      if (c) ep.class_id = *c;
    }
  }
  return cloud;
}

}  // namespace semsegmap
