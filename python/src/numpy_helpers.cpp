// The numpy conversions every binding file uses (bindings.h).
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "bindings.h"

namespace semsegmap::python {

std::string shapeText(const py::array& a) {
  std::string text = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) text += (i ? ", " : "") + std::to_string(a.shape(i));
  return text + (a.ndim() == 1 ? ",)" : ")");
}

py::array_t<double> poseArray(const Pose& T) {
  py::array_t<double> a({4, 4});
  auto r = a.mutable_unchecked<2>();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r(i, j) = T.matrix()(i, j);
  return a;
}

Pose poseFrom(const py::array_t<double, py::array::forcecast>& a, const std::string& what) {
  if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
    throw std::invalid_argument(what + ": expected a 4x4 pose, got shape " + shapeText(a));
  const auto r = a.unchecked<2>();
  // Isometry3d keeps only the upper 3x4 block: a projective last row would be dropped silently.
  for (int j = 0; j < 4; ++j)
    if (std::abs(r(3, j) - (j == 3 ? 1.0 : 0.0)) > 1e-9)
      throw std::invalid_argument(what + ": the last row of a pose must be 0 0 0 1");
  Pose T = Pose::Identity();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) T.matrix()(i, j) = r(i, j);
  return T;
}

py::array_t<double> posesArray(const std::vector<Pose>& poses) {
  py::array_t<double> a({poses.size(), size_t{4}, size_t{4}});
  auto r = a.mutable_unchecked<3>();
  for (size_t k = 0; k < poses.size(); ++k)
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) r(k, i, j) = poses[k].matrix()(i, j);
  return a;
}

std::string attributesRepr(const py::object& self, const std::string& type,
                           const std::vector<std::string>& names) {
  std::string text = type + "(";
  for (size_t i = 0; i < names.size(); ++i) {
    const py::object value = self.attr(names[i].c_str());
    const py::object shown = py::isinstance<py::float_>(value)
                                 ? py::str("{:.4g}").attr("format")(value)
                                 : py::repr(value);
    text += (i ? ", " : "") + names[i] + "=" + shown.cast<std::string>();
  }
  return text + ")";
}

void makeReadOnly(py::array& a) {
  a.attr("setflags")(py::arg("write") = false);
}

EnrichedCloud enrichedCloudFrom(const py::array& a, const std::string& what) {
  if (py::isinstance<py::array_t<EnrichedPoint>>(a)) {
    if (a.ndim() != 1)
      throw std::invalid_argument(what + ": expected a 1-d array of enriched points, got shape " +
                                  shapeText(a));
    const auto contiguous = py::array_t<EnrichedPoint, py::array::c_style>::ensure(a);
    EnrichedCloud cloud(static_cast<size_t>(contiguous.size()));
    if (!cloud.empty())
      std::memcpy(cloud.data(), contiguous.data(), cloud.size() * sizeof(cloud[0]));
    return cloud;
  }
  if (a.dtype().has_fields())
    throw std::invalid_argument(what +
                                ": a structured array must have the dtype "
                                "ENRICHED_POINT_DTYPE");
  const auto xyz = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!xyz || xyz.ndim() != 2 || xyz.shape(1) != 3)
    throw std::invalid_argument(
        what + ": expected (K, 3) points or ENRICHED_POINT_DTYPE, got shape " + shapeText(a));
  const auto r = xyz.unchecked<2>();
  EnrichedCloud cloud(static_cast<size_t>(xyz.shape(0)));
  for (size_t i = 0; i < cloud.size(); ++i) {
    cloud[i].x = r(i, 0);
    cloud[i].y = r(i, 1);
    cloud[i].z = r(i, 2);
  }
  return cloud;
}

py::array_t<float> pointsArray(const std::vector<Eigen::Vector3f>& points) {
  py::array_t<float> a({points.size(), size_t{3}});
  auto r = a.mutable_unchecked<2>();
  for (size_t i = 0; i < points.size(); ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = points[i][j];
  return a;
}

std::vector<Eigen::Vector3f> pointsFrom(const py::array_t<float, py::array::forcecast>& a,
                                        const std::string& what) {
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw std::invalid_argument(what + ": expected (K, 3) points, got shape " + shapeText(a));
  const auto r = a.unchecked<2>();
  std::vector<Eigen::Vector3f> points(static_cast<size_t>(a.shape(0)));
  for (size_t i = 0; i < points.size(); ++i) points[i] = {r(i, 0), r(i, 1), r(i, 2)};
  return points;
}

}  // namespace semsegmap::python
