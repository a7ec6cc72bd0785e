// What the binding files share: one bind function per library folder (module.cpp calls them in
// order, so that a class is registered before a signature names it) and the numpy conversions.
//
// Arrays out of the library are views into the C++ object (numpy base: the Python object that
// owns it) where its memory is one contiguous block of the element type; poses and fields gathered
// from structs are copies. Arrays into the library are copied: the library owns its values.
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>
#include <pybind11/stl_bind.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "semsegmap/core/enriched_point.h"
#include "semsegmap/core/frame.h"
#include "semsegmap/core/pose.h"
#include "semsegmap/core/sensor_rig.h"

// The rig's cameras as a list that edits the rig in place (rig.cameras.append(...)), instead of
// a copy that silently drops the edit.
PYBIND11_MAKE_OPAQUE(std::vector<semsegmap::Camera>)

namespace semsegmap::python {

namespace py = pybind11;

void bindCore(py::module_& m);
void bindConfig(py::module_& m);
void bindDatasets(py::module_& m);
void bindDescribe(py::module_& m);
void bindLive(py::module_& m);
void bindLocalize(py::module_& m);
void bindPipeline(py::module_& m);
void bindSim(py::module_& m);

// "(3, 4)": an array's shape as numpy prints it, for error messages.
std::string shapeText(const py::array& a);

// A pose as a 4x4 float64 array (a copy), and back: `what` names the argument in the
// std::invalid_argument (ValueError) thrown for another shape or a last row other than 0 0 0 1.
py::array_t<double> poseArray(const Pose& T);
Pose poseFrom(const py::array_t<double, py::array::forcecast>& a, const std::string& what);
// Poses as an (N, 4, 4) float64 array.
py::array_t<double> posesArray(const std::vector<Pose>& poses);

// A view of `count` rows of `cols` T each, starting at `data`, `row_bytes` apart; `owner` keeps
// the memory alive. `count` 0 gives an empty array that owns its (no) memory.
template <typename T>
py::array_t<T> rowsView(const void* data, size_t count, size_t cols, size_t row_bytes,
                        py::handle owner) {
  return py::array_t<T>({count, cols}, {row_bytes, sizeof(T)}, static_cast<const T*>(data), owner);
}

// A vector handed to numpy without a copy: the array owns it from now on.
template <typename T>
py::array_t<T> ownedArray(std::vector<T>&& values) {
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule free(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>({owned->size()}, {sizeof(T)}, owned->data(), free);
}

// A plain struct (configs, records): its fields read and written by name (an unknown name is an
// AttributeError, as a typo must not go unnoticed), keyword construction with the same names, a
// repr listing the fields, `_fields` naming them in order, and copy.copy / copy.deepcopy.
template <typename T>
class StructBinding {
 public:
  StructBinding(py::handle scope, const char* name, const char* doc)
      : cls_(scope, name, doc), names_(std::make_shared<std::vector<std::string>>()) {
    cls_.def(py::init([](const py::kwargs& fields) {
               py::object o = py::cast(T{});
               for (const auto& kv : fields) py::setattr(o, kv.first, kv.second);
               return o.cast<T>();
             }),
             "Defaults, with the fields given by keyword replaced.");
    cls_.def("__copy__", [](const T& t) { return T(t); });
    cls_.def(
        "__deepcopy__", [](const T& t, const py::dict&) { return T(t); }, py::arg("memo"));
    cls_.def("__repr__", [names = names_, type = std::string(name)](const py::object& self) {
      std::string text = type + "(";
      for (size_t i = 0; i < names->size(); ++i)
        text += (i ? ", " : "") + (*names)[i] + "=" +
                py::repr(self.attr((*names)[i].c_str())).template cast<std::string>();
      return text + ")";
    });
  }

  template <typename M>
  StructBinding& field(const char* name, M T::*member, const char* doc = "") {
    cls_.def_readwrite(name, member, doc);
    return named(name);
  }
  template <typename Get, typename Set>
  StructBinding& property(const char* name, Get get, Set set, const char* doc = "") {
    cls_.def_property(name, get, set, doc);
    return named(name);
  }
  py::class_<T>& cls() { return cls_; }

 private:
  StructBinding& named(const char* name) {
    names_->push_back(name);
    cls_.attr("_fields") = py::tuple(py::cast(*names_));
    return *this;
  }
  py::class_<T> cls_;
  std::shared_ptr<std::vector<std::string>> names_;
};

// "Type(a=1, b=2.5, c=None)": a result's key numbers, read from the attributes named (floats to
// 4 significant digits, anything else as Python shows it), so that a result printed at the
// prompt says what it holds instead of its address.
std::string attributesRepr(const py::object& self, const std::string& type,
                           const std::vector<std::string>& names);
template <typename Class>
Class& defRepr(Class& cls, const char* type, std::vector<std::string> names) {
  return cls.def("__repr__", [type = std::string(type), names](const py::object& self) {
    return attributesRepr(self, type, names);
  });
}

// Makes an array read-only: views of what the library shares (a target map's descriptors).
void makeReadOnly(py::array& a);

// Enriched points (the EnrichedPoint structured dtype) or plain (K, 3) xyz arrays (no colour,
// class unknown), copied; `what` names the argument in errors.
EnrichedCloud enrichedCloudFrom(const py::array& a, const std::string& what);
// An (N, 3) float32 array of points (a copy).
py::array_t<float> pointsArray(const std::vector<Eigen::Vector3f>& points);
std::vector<Eigen::Vector3f> pointsFrom(const py::array_t<float, py::array::forcecast>& a,
                                        const std::string& what);
// (H, W, 3) uint8 colour (channels 3) or (H, W) class ids (channels 1), copied; `what` names
// the argument in errors.
Image imageFrom(const py::array_t<uint8_t, py::array::c_style | py::array::forcecast>& a,
                int channels, const std::string& what);
// A frame from numpy arrays (copied), as Frame(points, ...) takes them.
Frame frameFrom(const py::array_t<float, py::array::c_style | py::array::forcecast>& points,
                const py::object& point_labels, const py::object& point_times,
                const py::object& images, const py::object& label_images,
                const py::object& T_odom_base, const py::object& T_world_base, size_t index,
                double timestamp_s);

}  // namespace semsegmap::python
