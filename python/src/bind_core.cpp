// core/: frames as numpy arrays (views into the frame), the sensor rig, the class table, the
// dataset's description, enriched points as a numpy structured dtype.
#include <stdexcept>

#include "bindings.h"
#include "semsegmap/core/class_table.h"
#include "semsegmap/core/frame.h"
#include "semsegmap/core/frame_source.h"

namespace semsegmap::python {

namespace {

// The layouts the views rely on.
static_assert(sizeof(LidarPoint) == 4 * sizeof(float), "LidarPoint is x, y, z, intensity");
static_assert(sizeof(PointLabel) == 2 * sizeof(uint16_t), "PointLabel is class, instance");

using FloatIn = py::array_t<float, py::array::c_style | py::array::forcecast>;
using U16In = py::array_t<uint16_t, py::array::c_style | py::array::forcecast>;
using U8In = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>;

// (N, 3) or (N, 4) points: intensity 0 when not given.
std::vector<LidarPoint> lidarPointsFrom(const FloatIn& a) {
  if (a.ndim() != 2 || (a.shape(1) != 3 && a.shape(1) != 4))
    throw std::invalid_argument("points: expected an (N, 3) or (N, 4) array, got shape " +
                                shapeText(a));
  const auto r = a.unchecked<2>();
  std::vector<LidarPoint> points(static_cast<size_t>(a.shape(0)));
  for (size_t i = 0; i < points.size(); ++i)
    points[i] = {r(i, 0), r(i, 1), r(i, 2), a.shape(1) == 4 ? r(i, 3) : 0.0f};
  return points;
}

// (N, 2) class and instance, or (N,) classes (instance 0).
std::vector<PointLabel> pointLabelsFrom(const U16In& a, size_t points) {
  const bool classes_only = a.ndim() == 1;
  if ((!classes_only && (a.ndim() != 2 || a.shape(1) != 2)) ||
      static_cast<size_t>(a.shape(0)) != points)
    throw std::invalid_argument("point_labels: expected (" + std::to_string(points) +
                                ", 2) [class, instance] or (" + std::to_string(points) +
                                ",) classes, one per point, got shape " + shapeText(a));
  std::vector<PointLabel> labels(points);
  const uint16_t* d = a.data();
  for (size_t i = 0; i < points; ++i)
    labels[i] = classes_only ? PointLabel{d[i], 0} : PointLabel{d[2 * i], d[2 * i + 1]};
  return labels;
}

std::vector<float> pointTimesFrom(const FloatIn& a, size_t points) {
  if (a.ndim() != 1 || static_cast<size_t>(a.shape(0)) != points)
    throw std::invalid_argument("point_times: expected (" + std::to_string(points) +
                                ",), one per point, got shape " + shapeText(a));
  return std::vector<float>(a.data(), a.data() + points);
}

// Camera k's picture of `images` (a list, None entries for none) into frame.cameras.
void setImages(Frame& f, const py::object& images, int channels, const char* what) {
  if (images.is_none()) return;
  const auto list = images.cast<py::list>();
  if (f.cameras.size() < list.size()) f.cameras.resize(list.size());
  for (size_t k = 0; k < list.size(); ++k) {
    if (list[k].is_none()) continue;
    Image image = imageFrom(list[k].cast<U8In>(), channels,
                            std::string(what) + "[" + std::to_string(k) + "]");
    (channels == 3 ? f.cameras[k].rgb : f.cameras[k].label) = std::move(image);
  }
}

}  // namespace

Image imageFrom(const py::array_t<uint8_t, py::array::c_style | py::array::forcecast>& a,
                int channels, const std::string& what) {
  const bool ok = channels == 3 ? a.ndim() == 3 && a.shape(2) == 3
                                : a.ndim() == 2 || (a.ndim() == 3 && a.shape(2) == 1);
  if (!ok)
    throw std::invalid_argument(what + ": expected " +
                                (channels == 3 ? "(H, W, 3) uint8 RGB" : "(H, W) uint8 class ids") +
                                ", got shape " + shapeText(a));
  Image image(static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)), channels);
  std::copy(a.data(), a.data() + image.data.size(), image.data.begin());
  return image;
}

Frame frameFrom(const FloatIn& points, const py::object& point_labels,
                const py::object& point_times, const py::object& images,
                const py::object& label_images, const py::object& T_odom_base,
                const py::object& T_world_base, size_t index, double timestamp_s) {
  Frame f;
  f.index = index;
  f.timestamp_s = timestamp_s;
  f.points = lidarPointsFrom(points);
  if (!point_labels.is_none())
    f.point_labels = pointLabelsFrom(point_labels.cast<U16In>(), f.points.size());
  if (!point_times.is_none())
    f.point_times = pointTimesFrom(point_times.cast<FloatIn>(), f.points.size());
  setImages(f, images, 3, "images");
  setImages(f, label_images, 1, "label_images");
  if (!T_odom_base.is_none())
    f.T_odom_base =
        poseFrom(T_odom_base.cast<py::array_t<double, py::array::forcecast>>(), "T_odom_base");
  if (!T_world_base.is_none())
    f.T_world_base =
        poseFrom(T_world_base.cast<py::array_t<double, py::array::forcecast>>(), "T_world_base");
  return f;
}

namespace {

// An image as a view: (H, W, 3) colour or (H, W) labels; None when the camera has none.
py::object imageView(const Image& image, py::handle owner) {
  if (image.empty()) return py::none();
  const size_t h = image.height, w = image.width, c = image.channels;
  if (c == 1) return py::array_t<uint8_t>({h, w}, {w, size_t{1}}, image.data.data(), owner);
  return py::array_t<uint8_t>({h, w, c}, {w * c, c, size_t{1}}, image.data.data(), owner);
}

py::list imageViews(const py::object& self, bool labels) {
  py::list out;
  for (const CameraFrame& c : self.cast<const Frame&>().cameras)
    out.append(imageView(labels ? c.label : c.rgb, self));
  return out;
}

void bindFrame(py::module_& m) {
  py::class_<Frame>(m, "Frame",
                    "One synchronised capture of the rig (core/frame.h). Its arrays are views into "
                    "the frame: writing them changes the frame, and they stay valid while any of "
                    "them or the frame is alive. The arrays are fixed at construction; poses, "
                    "index and time can be set.")
      .def(py::init(&frameFrom), py::arg("points"), py::kw_only(),
           py::arg("point_labels") = py::none(), py::arg("point_times") = py::none(),
           py::arg("images") = py::none(), py::arg("label_images") = py::none(),
           py::arg("T_odom_base") = py::none(), py::arg("T_world_base") = py::none(),
           py::arg("index") = 0, py::arg("timestamp_s") = 0.0,
           "A frame from numpy arrays (copied): points (N, 3) or (N, 4) x y z [intensity] in the "
           "LiDAR frame; point_labels (N, 2) class and instance or (N,) classes; point_times (N,) "
           "seconds after timestamp_s; images and label_images one per rig camera, (H, W, 3) RGB "
           "and (H, W) class ids (None for a camera without); poses 4x4.")
      .def_readwrite("index", &Frame::index)
      .def_readwrite("number", &Frame::number,
                     "the dataset's own number of the frame (its scan's name), or None")
      .def_readwrite("timestamp_s", &Frame::timestamp_s)
      .def_property_readonly(
          "points",
          [](const py::object& self) {
            const auto& p = self.cast<const Frame&>().points;
            return rowsView<float>(p.data(), p.size(), 4, sizeof(LidarPoint), self);
          },
          "(N, 4) float32 view: x, y, z, intensity in the LiDAR frame")
      .def_property_readonly(
          "point_labels",
          [](const py::object& self) {
            const auto& l = self.cast<const Frame&>().point_labels;
            return rowsView<uint16_t>(l.data(), l.size(), 2, sizeof(PointLabel), self);
          },
          "(N, 2) uint16 view: class id and instance id per point; (0, 2) without labels")
      .def_property_readonly(
          "point_times",
          [](const py::object& self) {
            const auto& t = self.cast<const Frame&>().point_times;
            return py::array_t<float>({t.size()}, {sizeof(float)}, t.data(), self);
          },
          "(N,) float32 view: seconds after timestamp_s; empty without per-point times")
      .def_property_readonly(
          "images", [](const py::object& self) { return imageViews(self, false); },
          "per camera: an (H, W, 3) uint8 RGB view, or None")
      .def_property_readonly(
          "label_images", [](const py::object& self) { return imageViews(self, true); },
          "per camera: an (H, W) uint8 view of class ids, or None")
      .def_property(
          "T_odom_base", [](const Frame& f) { return poseArray(f.T_odom_base); },
          [](Frame& f, const py::array_t<double, py::array::forcecast>& T) {
            f.T_odom_base = poseFrom(T, "T_odom_base");
          },
          "4x4 float64 (a copy): the base in the odometry frame")
      .def_property(
          "T_world_base",
          [](const Frame& f) -> py::object {
            if (!f.T_world_base) return py::none();
            return poseArray(*f.T_world_base);
          },
          [](Frame& f, const py::object& T) {
            if (T.is_none())
              f.T_world_base.reset();
            else
              f.T_world_base =
                  poseFrom(T.cast<py::array_t<double, py::array::forcecast>>(), "T_world_base");
          },
          "4x4 float64 ground truth (a copy), or None");
}

void bindRig(py::module_& m) {
  StructBinding<LidarModel>(m, "LidarModel",
                            "The LiDAR's beam pattern and noise (core/sensor_rig.h)")
      .field("columns", &LidarModel::columns)
      .field("rows", &LidarModel::rows)
      .field("hfov_deg", &LidarModel::hfov_deg)
      .field("vfov_up_deg", &LidarModel::vfov_up_deg)
      .field("vfov_down_deg", &LidarModel::vfov_down_deg)
      .field("min_range_m", &LidarModel::min_range_m)
      .field("max_range_m", &LidarModel::max_range_m)
      .field("range_noise_m", &LidarModel::range_noise_m)
      .field("dropout", &LidarModel::dropout)
      .cls()
      .def("beam_direction", &LidarModel::beamDirection, py::arg("row"), py::arg("col"));

  StructBinding<Camera>(m, "Camera", "A camera in the OpenCV convention (core/sensor_rig.h)")
      .field("name", &Camera::name)
      .field("width", &Camera::width)
      .field("height", &Camera::height)
      .field("fx", &Camera::fx)
      .field("fy", &Camera::fy)
      .field("cx", &Camera::cx)
      .field("cy", &Camera::cy)
      .property(
          "model", [](const Camera& c) { return std::string(cameraModelName(c.model)); },
          [](Camera& c, const std::string& name) { c.model = parseCameraModel(name); },
          "pinhole | radtan | equidistant")
      .field("distortion", &Camera::distortion, "radtan: k1 k2 p1 p2 k3; equidistant: k1..k4")
      .property(
          "T_camera_lidar", [](const Camera& c) { return poseArray(c.T_camera_lidar); },
          [](Camera& c, const py::array_t<double, py::array::forcecast>& T) {
            c.T_camera_lidar = poseFrom(T, "T_camera_lidar");
          },
          "4x4: LiDAR points into the camera frame")
      .cls()
      .def("project", &Camera::project, py::arg("p_camera"),
           "The pixel (u, v) of a point in the camera frame, or None")
      .def("pixel_ray", &Camera::pixelRay, py::arg("u"), py::arg("v"));

  py::bind_vector<std::vector<Camera>>(m, "CameraList");

  StructBinding<SensorRig>(m, "SensorRig", "A LiDAR and cameras with their calibration")
      .field("lidar", &SensorRig::lidar)
      .property(
          "T_base_lidar", [](const SensorRig& r) { return poseArray(r.T_base_lidar); },
          [](SensorRig& r, const py::array_t<double, py::array::forcecast>& T) {
            r.T_base_lidar = poseFrom(T, "T_base_lidar");
          },
          "4x4: the LiDAR on the base")
      .field("cameras", &SensorRig::cameras, "in the order of Frame.images")
      .field("rate_hz", &SensorRig::rate_hz)
      .cls()
      .def("validate", &SensorRig::validate, "Raises ValueError naming the field that is wrong");
  m.def("default_sim_rig", &defaultSimRig, "The paper's simulated rig");
}

void bindClasses(py::module_& m) {
  StructBinding<SemanticClass>(m, "SemanticClass", "A class of the class table")
      .field("id", &SemanticClass::id)
      .field("name", &SemanticClass::name)
      .field("color_rgb", &SemanticClass::color_rgb)
      .field("dynamic", &SemanticClass::dynamic)
      .field("ground", &SemanticClass::ground);
  py::class_<ClassTable>(m, "ClassTable", "The semantic classes (core/class_table.h)")
      .def(py::init<std::vector<SemanticClass>>(), py::arg("classes"))
      .def_static("default", &ClassTable::Default, "The simulator's table")
      .def_property_readonly("classes", &ClassTable::classes)
      .def("contains", &ClassTable::contains, py::arg("id"))
      .def("at", &ClassTable::at, py::arg("id"), "Raises IndexError for an id not in the table")
      .def("find", &ClassTable::find, py::arg("name"), "The id of a class name, or None")
      .def("__len__", [](const ClassTable& t) { return t.classes().size(); });
}

void bindDatasetInfo(py::module_& m) {
  StructBinding<DatasetInfo>(m, "DatasetInfo", "What a dataset is (core/frame_source.h)")
      .field("name", &DatasetInfo::name)
      .field("rig", &DatasetInfo::rig)
      .field("classes", &DatasetInfo::classes)
      .field("has_ground_truth_poses", &DatasetInfo::has_ground_truth_poses)
      .field("has_odometry", &DatasetInfo::has_odometry)
      .field("odometry_is_ground_truth", &DatasetInfo::odometry_is_ground_truth)
      .field("has_frame_times", &DatasetInfo::has_frame_times)
      .field("has_point_labels", &DatasetInfo::has_point_labels)
      .field("point_labels_have_classes", &DatasetInfo::point_labels_have_classes)
      .field("first_transient_instance", &DatasetInfo::first_transient_instance);
}

}  // namespace

void bindCore(py::module_& m) {
  PYBIND11_NUMPY_DTYPE(EnrichedPoint, x, y, z, h, s, v, class_id, has_color, has_class,
                       instance_id);
  m.attr("ENRICHED_POINT_DTYPE") = py::dtype::of<EnrichedPoint>();
  bindFrame(m);
  bindRig(m);
  bindClasses(m);
  bindDatasetInfo(m);
}

}  // namespace semsegmap::python
