// localize/ and artefacts/map_file.h: target maps built, saved, loaded and localized against. A
// target map is immutable from Python (its arrays are read-only): localizers share it.
#include <stdexcept>

#include "bindings.h"
#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/store/map_location.h"
#include "semsegmap/describe/descriptor.h"
#include "semsegmap/localize/localizer.h"
#include "semsegmap/localize/target_map.h"
#include "semsegmap/pipeline/map_parameters.h"

namespace semsegmap::python {

namespace {

using FloatIn = py::array_t<float, py::array::forcecast>;

const MapSegment& segmentAt(const TargetMap& map, size_t i) {
  if (i >= map.size())
    throw std::out_of_range("target map: segment " + std::to_string(i) + " out of range (" +
                            std::to_string(map.size()) + " segments)");
  return map.segments[i];
}

// A per-segment field of the map as an (M,) or (M, 3) array (a copy: the segments are structs).
template <typename T, typename F>
py::array_t<T> perSegment(const TargetMap& map, F field) {
  py::array_t<T> a(static_cast<py::ssize_t>(map.size()));
  for (size_t i = 0; i < map.size(); ++i) a.mutable_at(i) = field(map.segments[i]);
  return a;
}

void bindMapSegment(py::module_& m) {
  StructBinding<MapSegment>(m, "MapSegment", "A segment of a target map (localize/target_map.h)")
      .property(
          "centroid", [](const MapSegment& s) { return Eigen::Vector3f(s.centroid); },
          [](MapSegment& s, const Eigen::Vector3f& c) { s.centroid = c; }, "(3,) map frame")
      .field("n_points", &MapSegment::n_points)
      .field("majority_class", &MapSegment::majority_class)
      .property(
          "points", [](const MapSegment& s) { return pointsArray(s.points); },
          [](MapSegment& s, const FloatIn& p) { s.points = pointsFrom(p, "points"); },
          "(K, 3) float32 (a copy): optional points, map frame");
}

py::dict parametersDict(const MapParameters& parameters) {
  py::dict d;
  for (const auto& [key, value] : parameters) d[py::str(key)] = value;
  return d;
}

void bindTargetMap(py::module_& m) {
  py::class_<TargetMap, std::shared_ptr<TargetMap>>(
      m, "TargetMap", "What a robot localizes against (localize/target_map.h); read-only")
      .def_readonly("descriptor", &TargetMap::descriptor, "the describer's kind")
      .def_readonly("fingerprint", &TargetMap::fingerprint)
      .def_readonly("source", &TargetMap::source, "the file it was loaded from, or ''")
      .def_property_readonly(
          "parameters", [](const TargetMap& map) { return parametersDict(map.parameters); },
          "dict of the settings the map was built with (pipeline/map_parameters.h), a copy")
      .def("__len__", &TargetMap::size)
      .def(
          "__repr__",
          [](const TargetMap& map) {
            return "TargetMap(descriptor=" + py::repr(py::str(map.descriptor)).cast<std::string>() +
                   ", segments=" + std::to_string(map.size()) +
                   ", dimension=" + std::to_string(map.dimension()) +
                   ", source=" + py::repr(py::str(map.source)).cast<std::string>() + ")";
          })
      .def_property_readonly("dimension", &TargetMap::dimension)
      .def_property_readonly(
          "descriptors",
          [](const py::object& self) {
            const Eigen::MatrixXf& d = self.cast<const TargetMap&>().descriptors;
            // Column-major: a read-only (M, D) view with Fortran strides.
            py::array a = py::array_t<float>({size_t(d.rows()), size_t(d.cols())},
                                             {sizeof(float), sizeof(float) * size_t(d.rows())},
                                             d.data(), self);
            makeReadOnly(a);
            return a;
          },
          "(M, D) float32 read-only view, one row per segment")
      .def_property_readonly(
          "centroids",
          [](const TargetMap& map) {
            std::vector<Eigen::Vector3f> c;
            for (const MapSegment& s : map.segments) c.push_back(s.centroid);
            return pointsArray(c);
          },
          "(M, 3) float32 (a copy), map frame")
      .def_property_readonly(
          "n_points",
          [](const TargetMap& map) {
            return perSegment<uint32_t>(map, [](const MapSegment& s) { return s.n_points; });
          },
          "(M,) uint32 (a copy)")
      .def_property_readonly(
          "classes",
          [](const TargetMap& map) {
            return perSegment<ClassId>(map, [](const MapSegment& s) { return s.majority_class; });
          },
          "(M,) uint16 majority class per segment (a copy)")
      .def("segment", &segmentAt, py::arg("index"), "MapSegment `index` (a copy)");
}

void bindBuilder(py::module_& m) {
  py::class_<TargetMapBuilder>(m, "TargetMapBuilder",
                               "Collects segments into a target map, replacing duplicates")
      .def(py::init<std::string, std::string, int, const TargetMapBuilderConfig&>(),
           py::arg("descriptor"), py::arg("fingerprint"), py::arg("dimension"),
           py::arg("config") = TargetMapBuilderConfig{})
      .def("add", &TargetMapBuilder::add, py::arg("segment"), py::arg("descriptor"),
           "ValueError for a descriptor of another dimension or a non-finite value")
      .def(
          "set_parameters",
          [](TargetMapBuilder& b, const PipelineConfig& config) {
            b.setParameters(mapParametersOf(config));
          },
          py::arg("config"), "records the settings of `config` in the maps it builds")
      .def_property_readonly("duplicates_removed", &TargetMapBuilder::duplicatesRemoved)
      .def("build",
           [](const TargetMapBuilder& b) { return std::make_shared<TargetMap>(b.build()); });
}

void bindLocalizer(py::module_& m) {
  py::class_<Localization> localization(m, "Localization",
                                        "A match of the local segments against the map");
  defRepr(localization, "Localization", {"inliers", "candidates"});
  localization
      .def_property_readonly("T_map_local",
                             [](const Localization& l) { return poseArray(l.T_map_local); })
      .def_readonly("inliers", &Localization::inliers)
      .def_readonly("candidates", &Localization::candidates)
      .def_property_readonly(
          "matches",
          [](const Localization& l) {
            py::array_t<int64_t> a({l.matches.size(), size_t{2}});
            auto r = a.mutable_unchecked<2>();
            for (size_t i = 0; i < l.matches.size(); ++i) {
              r(i, 0) = static_cast<int64_t>(l.matches[i].first);
              r(i, 1) = static_cast<int64_t>(l.matches[i].second);
            }
            return a;
          },
          "(K, 2) int64: query row, target segment");
  py::class_<Localizer>(m, "Localizer", "Localizes local segments against a shared target map")
      .def(py::init([](std::shared_ptr<TargetMap> map, const LocalizerConfig& config) {
             py::gil_scoped_release release;  // builds the descriptor index
             return std::make_unique<Localizer>(std::shared_ptr<const TargetMap>(std::move(map)),
                                                config);
           }),
           py::arg("map"), py::arg("config") = LocalizerConfig{})
      .def(
          "localize",
          [](const Localizer& l, const FloatIn& centroids, const Eigen::MatrixXf& descriptors) {
            const std::vector<Eigen::Vector3f> c = pointsFrom(centroids, "centroids");
            // faiss reads rows of the map's dimension whatever the matrix has.
            if (descriptors.rows() > 0 && descriptors.cols() != l.map().dimension())
              throw std::invalid_argument(
                  "descriptors: expected " + std::to_string(l.map().dimension()) +
                  " columns (the map's dimension), got " + std::to_string(descriptors.cols()));
            py::gil_scoped_release release;
            return l.localize(c, descriptors);
          },
          py::arg("centroids"), py::arg("descriptors"),
          "Localization of (M, 3) centroids (local map frame) with (M, D) descriptors, or None")
      .def_property_readonly("config", &Localizer::config);
}

}  // namespace

void bindLocalize(py::module_& m) {
  bindMapSegment(m);
  bindTargetMap(m);
  bindBuilder(m);
  bindLocalizer(m);
  m.def(
      "save_map",
      [](const std::filesystem::path& path, const TargetMap& map, bool float16) {
        MapWriteOptions options;
        options.float16 = float16;
        py::gil_scoped_release release;
        return saveMapAt(path.string(), map, options, "python");
      },
      py::arg("path"), py::arg("map"), py::arg("float16") = true,
      "Writes a target map (docs/map-format.md), or a new map into a PostgreSQL store for a "
      "postgresql://...?map=NAME URI (docs/map-store.md); returns the file's size in bytes (0 "
      "for a store)");
  m.def(
      "load_map",
      [](const std::filesystem::path& path) {
        py::gil_scoped_release release;
        return std::make_shared<TargetMap>(loadMapAt(path.string()));
      },
      py::arg("path"),
      "A map file, or a map of a PostgreSQL store (postgresql://...?map=NAME[&region=X,Y,R], "
      "docs/map-store.md); RuntimeError '<path>: <what is wrong>' for a missing or corrupt file "
      "or a store that cannot be read");
  m.def(
      "check_map_compatible",
      [](const TargetMap& map, const Describer& d, const std::string& name) {
        checkMapCompatible(name, map, descriptorName(d.kind()), d.fingerprint(), d.dimension());
      },
      py::arg("map"), py::arg("describer"), py::arg("name") = "target map",
      "RuntimeError when the map's descriptors cannot be compared with the describer's");
  m.def(
      "map_parameters",
      [](const PipelineConfig& config) { return parametersDict(mapParametersOf(config)); },
      py::arg("config"), "dict of the settings of `config` a map records");
  m.def(
      "check_map_parameters",
      [](const TargetMap& map, const PipelineConfig& config, const std::string& name) {
        checkMapParameters(name, map, config, MapSettingsCheck::kRefuse);
      },
      py::arg("map"), py::arg("config"), py::arg("name") = "target map",
      "RuntimeError naming the first setting the map was built with otherwise than `config`");
}

}  // namespace semsegmap::python
