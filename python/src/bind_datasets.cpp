// datasets/: any --dataset spec opened as the command line opens it (apps/semsegmap/
// dataset_args.cpp), its frames read by index or iterated.
#include "bindings.h"
#include "semsegmap/core/frame_source.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/settings/config.h"

namespace semsegmap::python {

namespace {

// Reading a frame decodes files or renders it: without the GIL. The source is used by one thread
// at a time (as in C++), so a dataset must not be read from two Python threads at once.
Frame readFrame(FrameSource& source, size_t index) {
  py::gil_scoped_release release;
  return source.frame(index);
}

struct FrameIterator {
  std::shared_ptr<FrameSource> source;
  size_t next = 0;
};

// The shipped class maps, found by the package as the command line finds them.
std::filesystem::path shippedClassMaps() {
  return py::module_::import("semsegmap")
      .attr("shipped_file")("config/class_maps")
      .cast<std::filesystem::path>();
}

using Path = std::filesystem::path;

// The command line's --rig, --odometry, --ground-truth, --kitti-calib and --labels, and the
// --config whose odometry: and semantics: sections apply.
DatasetOptions optionsOf(const Path& rig, const Path& odometry, const Path& ground_truth,
                         const Path& kitti_calib, const Path& labels, const Path& config,
                         const Path& class_maps_dir) {
  DatasetOptions options;
  options.rig = rig;
  options.odometry = odometry;
  if (options.odometry == "lidar" && !config.empty())
    options.lidar_odometry = loadOdometryConfig(config);
  if (!config.empty()) options.semantics = loadSemanticsConfig(config);
  options.labels = labels;
  if (!options.semantics.model.empty() || !options.labels.empty())
    options.class_maps_dir = class_maps_dir.empty() ? shippedClassMaps() : class_maps_dir;
  options.ground_truth = ground_truth;
  options.kitti_calib = kitti_calib;
  return options;
}

std::shared_ptr<FrameSource> open(const std::string& spec, const Path& rig, const Path& odometry,
                                  const Path& ground_truth, const Path& kitti_calib,
                                  const Path& labels, const Path& config,
                                  const Path& class_maps_dir) {
  const DatasetOptions options =
      optionsOf(rig, odometry, ground_truth, kitti_calib, labels, config, class_maps_dir);
  py::gil_scoped_release release;
  return openDataset(spec, options);
}

std::pair<std::shared_ptr<FrameSource>, FrontEndStages> openForPipeline(
    const std::string& spec, const Path& rig, const Path& odometry, const Path& ground_truth,
    const Path& kitti_calib, const Path& labels, const Path& config, const Path& class_maps_dir) {
  const DatasetOptions options =
      optionsOf(rig, odometry, ground_truth, kitti_calib, labels, config, class_maps_dir);
  py::gil_scoped_release release;
  DatasetWithStages d = openDatasetForPipeline(spec, options);
  return {std::shared_ptr<FrameSource>(std::move(d.source)), std::move(d.stages)};
}

void bindFrontEndStages(py::module_& m) {
  py::class_<FrontEndStages> stages(
      m, "FrontEndStages",
      "The network and LiDAR odometry a Pipeline runs on each frame before enrichment "
      "(pipeline/front_end_stages.h); from open_dataset_for_pipeline");
  defRepr(stages, "FrontEndStages", {"network", "lidar_odometry"});
  stages.def(py::init<>(), "No stage: the frames' own labels and odometry")
      .def_property_readonly(
          "network", [](const FrontEndStages& s) { return s.network != nullptr; },
          "whether the semantics: network labels pictures without label images")
      .def_property_readonly(
          "lidar_odometry", [](const FrontEndStages& s) { return s.lidar_odometry.has_value(); },
          "whether LiDAR odometry gives each frame's pose");
}

}  // namespace

void bindDatasets(py::module_& m) {
  py::class_<FrameSource, std::shared_ptr<FrameSource>>(
      m, "Dataset",
      "Frames from a dataset (core/frame_source.h): ds[i], len(ds), for frame in ds. Reading "
      "releases the GIL; use a dataset from one thread at a time.")
      .def_property_readonly(
          "info", [](const FrameSource& s) { return s.info(); }, "DatasetInfo (a copy)")
      .def("__len__", &FrameSource::size)
      .def("frame", &readFrame, py::arg("index"),
           "Frame `index`; IndexError past the end, RuntimeError naming the file it cannot read")
      .def(
          "__getitem__",
          [](FrameSource& s, py::ssize_t i) {
            // Python's negative indices; past either end, the library's error.
            const py::ssize_t n = static_cast<py::ssize_t>(s.size());
            if (i < -n)
              throw std::out_of_range(s.info().name + ": frame " + std::to_string(i) +
                                      " out of range (" + std::to_string(n) + " frames)");
            return readFrame(s, static_cast<size_t>(i < 0 ? i + n : i));
          },
          py::arg("index"))
      .def(
          "frame_time",
          [](FrameSource& s, size_t i) {
            py::gil_scoped_release release;
            return s.frameTime(i);
          },
          py::arg("index"))
      .def("__iter__", [](const std::shared_ptr<FrameSource>& s) {
        return FrameIterator{s, 0};
      });

  py::class_<FrameIterator>(m, "DatasetIterator")
      .def("__iter__", [](FrameIterator& it) -> FrameIterator& { return it; })
      .def("__next__", [](FrameIterator& it) {
        if (it.next >= it.source->size()) throw py::stop_iteration();
        return readFrame(*it.source, it.next++);
      });

  bindFrontEndStages(m);
  m.def("open_dataset_for_pipeline", &openForPipeline, py::arg("spec"), py::kw_only(),
        py::arg("rig") = "", py::arg("odometry") = "", py::arg("ground_truth") = "",
        py::arg("kitti_calib") = "", py::arg("labels") = "", py::arg("config") = "",
        py::arg("class_maps_dir") = "",
        "open_dataset for a Pipeline or session that runs the network and LiDAR odometry "
        "itself: (the dataset without them, FrontEndStages to give as stages=)");
  m.def("open_dataset", &open, py::arg("spec"), py::kw_only(), py::arg("rig") = "",
        py::arg("odometry") = "", py::arg("ground_truth") = "", py::arg("kitti_calib") = "",
        py::arg("labels") = "", py::arg("config") = "", py::arg("class_maps_dir") = "",
        "Opens a --dataset SPEC as the command line does (datasets/open_dataset.h): DIR, "
        "kitti-raw:, semantickitti:, nclt:, folder:, rosbag:, sim:. The keywords are the "
        "command line's options (odometry: a TUM/KITTI file or 'lidar'); config: the YAML whose "
        "odometry: and semantics: sections apply. Errors name the spec or the file.");
}

}  // namespace semsegmap::python
