// The live core (pipeline/live_session.h) for a robot's Python program: messages in as its
// drivers publish them, poses out as they are found.
#include <memory>
#include <optional>

#include "bindings.h"
#include "semsegmap/pipeline/live_session.h"

namespace semsegmap::python {

namespace {

using FloatIn = py::array_t<float, py::array::c_style | py::array::forcecast>;
using U8In = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>;

// The localization session and the live session that works on it, in that order: the live
// session's worker calls the session, so it must stop first (members are destroyed in reverse).
struct LiveLocalizer {
  LocalizationSession session;
  LiveSession live;
  LiveLocalizer(const PipelineConfig& c, const DatasetInfo& info,
                std::shared_ptr<const TargetMap> map, std::shared_ptr<Describer> d,
                MapSettingsCheck check, const FrontEndStages& stages, const LiveConfig& live_config)
      : session(c, info, std::move(map), std::move(d), check, stages),
        live(live_config, localizingProcess(session)) {
    session.keepHistory(false);  // a robot's poses go out through poll(), as the node's do
  }
};

LiveConfig liveConfigOf(const DatasetInfo& info, bool odometry, size_t max_queued_frames,
                        bool never_drop, double picture_tolerance_s, double max_wait_s) {
  LiveConfig c;
  c.assembly.cameras = info.rig.cameras.size();
  c.assembly.odometry = odometry;
  c.assembly.picture_tolerance_s = picture_tolerance_s;
  c.assembly.max_wait_s = max_wait_s;
  c.max_queued_frames = max_queued_frames;
  c.never_drop = never_drop;
  return c;
}

void bindLiveResults(py::module_& m) {
  py::class_<LivePose> pose(m, "LivePose", "One localization as the live session gives it");
  defRepr(pose, "LivePose", {"latency_ms"});
  pose.def_readonly("record", &LivePose::record)
      .def_property_readonly(
          "T_map_odom", [](const LivePose& p) { return poseArray(p.T_map_odom); },
          "what a node publishes as map -> odom (4x4)")
      .def_property_readonly("T_odom_base",
                             [](const LivePose& p) { return poseArray(p.T_odom_base); })
      .def_readonly("latency_ms", &LivePose::latency_ms, "from the scan's arrival to its pose");
  py::class_<LiveStats> stats(m, "LiveStats", "What a live session received, did and dropped");
  defRepr(stats, "LiveStats", {"processed", "dropped", "localized", "mean_latency_ms"});
  stats.def_property_readonly("scans", [](const LiveStats& s) { return s.assembly.scans; })
      .def_property_readonly("frames", [](const LiveStats& s) { return s.assembly.frames; })
      .def_property_readonly("without_odometry",
                             [](const LiveStats& s) { return s.assembly.without_odometry; })
      .def_property_readonly("missing_pictures",
                             [](const LiveStats& s) { return s.assembly.missing_pictures; })
      .def_property_readonly("out_of_order",
                             [](const LiveStats& s) { return s.assembly.out_of_order; })
      .def_readonly("processed", &LiveStats::processed)
      .def_readonly("dropped", &LiveStats::dropped)
      .def_readonly("localized", &LiveStats::localized)
      .def_readonly("max_queued", &LiveStats::max_queued)
      .def_readonly("mean_latency_ms", &LiveStats::mean_latency_ms)
      .def_readonly("max_latency_ms", &LiveStats::max_latency_ms);
}

}  // namespace

void bindLive(py::module_& m) {
  bindLiveResults(m);
  py::class_<LiveLocalizer>(m, "LiveSession",
                            "Localizes as messages arrive: scans, pictures and odometry, each "
                            "with its time; a worker thread works on the frames made of them")
      .def(py::init([](const PipelineConfig& c, const DatasetInfo& info,
                       std::shared_ptr<TargetMap> map, std::shared_ptr<Describer> d, bool odometry,
                       size_t max_queued_frames, bool never_drop, double picture_tolerance_s,
                       double max_wait_s, const py::object& stages) {
             // LiDAR odometry or the network as stages (open_dataset_for_pipeline), or none.
             FrontEndStages s = stages.is_none() ? FrontEndStages{} : stages.cast<FrontEndStages>();
             // A robot's network runs beside the scans within its budget, never holding them up.
             s.labelling = FrontEndStages::Labelling::kLive;
             const LiveConfig live = liveConfigOf(info, odometry, max_queued_frames, never_drop,
                                                  picture_tolerance_s, max_wait_s);
             py::gil_scoped_release release;
             return std::make_unique<LiveLocalizer>(
                 c, info, std::shared_ptr<const TargetMap>(std::move(map)), std::move(d),
                 MapSettingsCheck::kRefuse, s, live);
           }),
           py::arg("config"), py::arg("info"), py::arg("map"), py::arg("describer"), py::kw_only(),
           py::arg("odometry") = true, py::arg("max_queued_frames") = 2,
           py::arg("never_drop") = false, py::arg("picture_tolerance_s") = 0.05,
           py::arg("max_wait_s") = 0.3, py::arg("stages") = py::none(),
           "info: the rig (pictures come for its cameras); odometry False: none comes (the "
           "stages' LiDAR odometry gives the poses); never_drop: the calls wait for the worker "
           "instead of dropping the oldest frame")
      .def(
          "add_scan",
          [](LiveLocalizer& l, double stamp_s, const FloatIn& points) {
            ScanMessage scan;
            scan.stamp_s = stamp_s;
            scan.points = frameFrom(points, py::none(), py::none(), py::none(), py::none(),
                                    py::none(), py::none(), 0, stamp_s)
                              .points;
            py::gil_scoped_release release;
            l.live.addScan(std::move(scan));
          },
          py::arg("stamp_s"), py::arg("points"), "points: (N, 3) or (N, 4) float32, LiDAR frame")
      .def(
          "add_picture",
          [](LiveLocalizer& l, size_t camera, double stamp_s, const py::object& rgb,
             const py::object& labels) {
            PictureMessage p;
            p.stamp_s = stamp_s;
            if (!rgb.is_none()) p.rgb = imageFrom(rgb.cast<U8In>(), 3, "rgb");
            if (!labels.is_none()) p.label = imageFrom(labels.cast<U8In>(), 1, "labels");
            py::gil_scoped_release release;
            l.live.addPicture(camera, std::move(p));
          },
          py::arg("camera"), py::arg("stamp_s"), py::arg("rgb") = py::none(),
          py::arg("labels") = py::none(), "camera: its index in the rig")
      .def(
          "add_odometry",
          [](LiveLocalizer& l, double stamp_s,
             const py::array_t<double, py::array::forcecast>& T_odom_base) {
            const StampedPose p{stamp_s, poseFrom(T_odom_base, "T_odom_base")};
            py::gil_scoped_release release;
            l.live.addOdometry(p);
          },
          py::arg("stamp_s"), py::arg("T_odom_base"))
      .def(
          "poll", [](LiveLocalizer& l) { return l.live.poll(); },
          "the LivePoses found since the last call")
      .def(
          "finish",
          [](LiveLocalizer& l) {
            py::gil_scoped_release release;
            l.live.finish();
          },
          "the end of the input: the waiting scans go with what they have, the worker works "
          "off its queue and stops")
      .def_property_readonly("stats", [](const LiveLocalizer& l) { return l.live.stats(); });
}

}  // namespace semsegmap::python
