// pipeline/: the front end frame by frame (Pipeline), its results and local segments, and the
// mapping and localization modes (pipeline/modes.h) by frame or over a whole dataset. Every call
// that processes frames releases the GIL.
#include <atomic>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "bindings.h"
#include "semsegmap/enrich/enricher.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/pipeline/pipeline.h"

namespace semsegmap::python {

namespace {

// The local segment map as arrays, one row per segment in ascending id (the query's order).
struct LocalSegments {
  py::array ids, centroids, n_points, classes, frame_indices, descriptors;
};

// A MappingRun whose map can be shared with localizers (TargetMap is held by shared_ptr).
struct MappingResult {
  std::shared_ptr<TargetMap> map;
  std::vector<Pose> trajectory;
  size_t segments = 0, duplicates_removed = 0;
  RunStats stats;
};

MappingResult resultOf(MappingRun&& run) {
  return {std::make_shared<TargetMap>(std::move(run.map)), std::move(run.trajectory), run.segments,
          run.duplicates_removed, run.stats};
}

std::shared_ptr<Describer> required(std::shared_ptr<Describer> d, const char* where) {
  if (!d)
    throw std::invalid_argument(std::string(where) + ": describer: required (make_describer)");
  return d;
}

MapSettingsCheck settingsCheck(bool allow_config_mismatch) {
  return allow_config_mismatch ? MapSettingsCheck::kWarn : MapSettingsCheck::kRefuse;
}

// The command line's default: ground truth when the dataset has it, else odometry.
// The front-end stages a Python caller gave (open_dataset_for_pipeline), or none.
FrontEndStages stagesOf(const py::object& stages) {
  return stages.is_none() ? FrontEndStages{} : stages.cast<FrontEndStages>();
}

PoseSource posesFor(const py::object& poses, const DatasetInfo& info) {
  if (poses.is_none())
    return info.has_ground_truth_poses ? PoseSource::kGroundTruth : PoseSource::kOdometry;
  return parsePoseSource(poses.cast<std::string>());
}

py::array_t<EnrichedPoint> cloudArray(EnrichedCloud cloud) {
  return ownedArray(std::move(cloud));
}

// semsegmap.StopFlag: a Python caller's request to stop a run between frames, set from another
// thread (the run releases the GIL) or a callback; the run ends with the frames done.
struct StopFlag {
  std::atomic<bool> requested{false};
};

// How a Python run stops between frames: at the caller's StopFlag, or at Ctrl-C. The library
// checks one flag (RunOptions::stop) before each frame; after each frame this sets it from the
// caller's flag, and from Python's pending signals (PyErr_CheckSignals, with the GIL): a
// KeyboardInterrupt then ends the run with the frame in hand finished and is raised after it
// (rethrow), as Ctrl-C would have raised it had the GIL been held.
class RunStop {
 public:
  explicit RunStop(const StopFlag* flag) : flag_(flag) { poll(); }
  void install(RunOptions& options) {
    options.stop = StopToken(stop_);
    options.progress = [this](size_t, size_t) {
      poll();
      py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() != 0) {
        signal_.emplace();  // fetches the error the signal's handler raised
        stop_ = true;
      }
    };
  }
  // With the GIL, after the run: the signal's error, if one stopped it.
  void rethrow() {
    if (signal_) throw std::move(*signal_);
  }

 private:
  void poll() {
    if (flag_ && flag_->requested.load()) stop_ = true;
  }
  const StopFlag* flag_;
  std::atomic<bool> stop_{false};
  std::optional<py::error_already_set> signal_;
};

// Descriptors (one vector each, all of one size) as an (M, D) matrix.
Eigen::MatrixXf rowsOf(const std::vector<Eigen::VectorXf>& d) {
  Eigen::MatrixXf m(static_cast<Eigen::Index>(d.size()), d.empty() ? 0 : d[0].size());
  for (size_t i = 0; i < d.size(); ++i) m.row(static_cast<Eigen::Index>(i)) = d[i].transpose();
  return m;
}

LocalSegments localSegmentsOf(const Pipeline& p) {
  const LocalSegmentQuery q = p.localSegmentQuery();
  std::vector<uint32_t> n_points;
  std::vector<ClassId> classes;
  std::vector<uint64_t> frames;
  for (SegmentId id : q.ids) {
    const DescribedSegment& s = p.localSegments().at(id);
    n_points.push_back(s.n_points);
    classes.push_back(s.majority_class);
    frames.push_back(s.frame_index);
  }
  std::vector<int64_t> ids(q.ids.begin(), q.ids.end());
  return {ownedArray(std::move(ids)),      pointsArray(q.centroids),
          ownedArray(std::move(n_points)), ownedArray(std::move(classes)),
          ownedArray(std::move(frames)),   py::cast(q.descriptors)};
}

// The points of a local segment's described observation (map frame), a copy.
py::array_t<EnrichedPoint> segmentPoints(const Pipeline& p, SegmentId id) {
  const Segment* s = p.segmenter().segment(id);
  if (!p.localSegments().count(id) || !s || s->observations.empty())
    throw std::out_of_range("segment " + std::to_string(id) + " is not in the local segment map");
  return cloudArray(s->last().points);
}

void bindResults(py::module_& m) {
  py::class_<StageTimes> times(m, "StageTimes", "Milliseconds per stage");
  times.def_readonly("enrich_ms", &StageTimes::enrich_ms)
      .def_readonly("local_map_ms", &StageTimes::local_map_ms)
      .def_readonly("segment_ms", &StageTimes::segment_ms)
      .def_readonly("describe_ms", &StageTimes::describe_ms)
      .def_readonly("localize_ms", &StageTimes::localize_ms)
      .def_property_readonly("total_ms", &StageTimes::total);
  defRepr(times, "StageTimes",
          {"enrich_ms", "local_map_ms", "segment_ms", "describe_ms", "localize_ms", "total_ms"});
  py::class_<RunStats> stats(m, "RunStats", "Frames processed and the pipeline's time over them");
  stats.def_readonly("frames", &RunStats::frames)
      .def_readonly("total", &RunStats::total)
      .def_readonly("interrupted", &RunStats::interrupted,
                    "a stop request (StopFlag, Ctrl-C) ended the run early: `frames` are those "
                    "done")
      .def_property_readonly("fps", &RunStats::fps);
  defRepr(stats, "RunStats", {"frames", "fps"});
  py::class_<StopFlag>(m, "StopFlag",
                       "A request to stop a run between frames: pass it as stop= to run_mapping "
                       "or run_localization and set() it, e.g. from another thread; the run "
                       "ends with the frames done (stats.interrupted)")
      .def(py::init<>())
      .def(
          "set", [](StopFlag& f) { f.requested = true; }, "ask the runs given this flag to stop")
      .def(
          "clear", [](StopFlag& f) { f.requested = false; }, "to use the flag for another run")
      .def_property_readonly(
          "is_set", [](const StopFlag& f) { return f.requested.load(); }, "whether set()");

  py::class_<SegmentObservation>(m, "SegmentObservation", "One observation of a segment")
      .def_readonly("frame_index", &SegmentObservation::frame_index)
      .def_readonly("timestamp_s", &SegmentObservation::timestamp_s)
      .def_readonly("n_points", &SegmentObservation::n_points)
      .def_readonly("centroid", &SegmentObservation::centroid, "(3,) float64, map frame")
      .def_readonly("majority_class", &SegmentObservation::majority_class)
      .def_readonly("gt_instance", &SegmentObservation::gt_instance)
      .def_readonly("gt_purity", &SegmentObservation::gt_purity)
      .def_property_readonly(
          "points",
          [](const py::object& self) {
            const EnrichedCloud& c = self.cast<const SegmentObservation&>().points;
            return py::array_t<EnrichedPoint>({c.size()}, {sizeof(EnrichedPoint)}, c.data(), self);
          },
          "ENRICHED_POINT_DTYPE view, map frame; empty for older observations unless kept");
  py::class_<Segment> segment(m, "Segment", "A segment and its observations (segment/segment.h)");
  defRepr(segment, "Segment", {"id", "first_frame", "last_frame"});
  segment.def_readonly("id", &Segment::id)
      .def_readonly("first_frame", &Segment::first_frame)
      .def_readonly("last_frame", &Segment::last_frame)
      .def_readonly("observations", &Segment::observations)
      .def_property_readonly(
          "last", [](const Segment& s) -> const SegmentObservation& { return s.last(); },
          py::return_value_policy::reference_internal, "the latest, most complete observation");

  py::class_<FrameResult> frame(m, "FrameResult", "What the front end did with one frame");
  defRepr(frame, "FrameResult", {"frame_index", "points", "described", "times"});
  frame.def_readonly("frame_index", &FrameResult::frame_index)
      .def_property_readonly("T_local_base",
                             [](const FrameResult& r) { return poseArray(r.T_local_base); })
      .def_readonly("points", &FrameResult::points)
      .def_readonly("colored_points", &FrameResult::colored_points)
      .def_readonly("described", &FrameResult::described, "segments described this frame")
      .def_readonly("times", &FrameResult::times)
      .def_property_readonly("points_inserted",
                             [](const FrameResult& r) { return r.map_update.points_inserted; })
      .def_property_readonly("points_filtered",
                             [](const FrameResult& r) { return r.map_update.points_filtered; })
      .def_property_readonly("newly_active_voxels",
                             [](const FrameResult& r) { return r.map_update.newly_active.size(); })
      .def_property_readonly("removed_voxels",
                             [](const FrameResult& r) { return r.map_update.removed.size(); })
      .def_property_readonly(
          "observed", [](const FrameResult& r) { return r.segmentation.observed; },
          "ids of the segments observed anew")
      .def_property_readonly(
          "merges",
          [](const FrameResult& r) {
            std::vector<std::pair<SegmentId, SegmentId>> merges;
            for (const SegmentMerge& g : r.segmentation.merges)
              merges.emplace_back(g.absorbed, g.survivor);
            return merges;
          },
          "(absorbed, survivor) id pairs")
      .def_property_readonly(
          "dropped", [](const FrameResult& r) { return r.segmentation.dropped; },
          "ids of the segments dropped as too large (max_segment_points) this frame")
      .def_property_readonly(
          "finished", [](const FrameResult& r) { return r.segmentation.finished; },
          "the segments that left the local map (copies)")
      .def_property_readonly(
          "finished_descriptors",
          [](const FrameResult& r) { return rowsOf(r.finished_descriptors); },
          "(M, D): their final descriptors, parallel to finished");

  py::class_<LocalSegments>(m, "LocalSegments",
                            "The local segment map as arrays, one row per segment by ascending id")
      .def_readonly("ids", &LocalSegments::ids, "(M,) int64")
      .def_readonly("centroids", &LocalSegments::centroids, "(M, 3) float32, local map frame")
      .def_readonly("n_points", &LocalSegments::n_points, "(M,) uint32")
      .def_readonly("classes", &LocalSegments::classes, "(M,) uint16 majority class")
      .def_readonly("frame_indices", &LocalSegments::frame_indices,
                    "(M,) uint64: frame of the described observation")
      .def_readonly("descriptors", &LocalSegments::descriptors, "(M, D) float32")
      .def("__len__", [](const LocalSegments& s) { return s.ids.size(); });
}

void bindPipelineClass(py::module_& m) {
  py::class_<Pipeline>(m, "Pipeline",
                       "The front end frame by frame: enrich, local map, segment, describe")
      .def(py::init([](const PipelineConfig& c, const DatasetInfo& info, const py::object& poses,
                       std::shared_ptr<Describer> d, const py::object& stages) {
             const FrontEndStages s = stagesOf(stages);
             return std::make_unique<Pipeline>(c, info, posesFor(poses, infoWithStages(info, s)),
                                               std::move(d), s);
           }),
           py::arg("config"), py::arg("info"), py::arg("poses") = py::none(),
           py::arg("describer") = nullptr, py::arg("stages") = py::none(),
           "poses: 'gt' or 'odom' (default: gt when the dataset has it); no describer: segments "
           "are not described; stages (FrontEndStages, from open_dataset_for_pipeline): the "
           "network and LiDAR odometry run on each frame before enrichment")
      .def(
          "process",
          [](Pipeline& p, const Frame& f) {
            py::gil_scoped_release release;
            return p.process(f);
          },
          py::arg("frame"))
      .def(
          "finish",
          [](Pipeline& p) {
            std::vector<Eigen::VectorXf> d;
            std::vector<Segment> segments;
            {
              py::gil_scoped_release release;
              segments = p.finish(p.describer() ? &d : nullptr);
            }
            return py::make_tuple(segments, rowsOf(d));
          },
          "End of the run: (segments still in the local map, finished; their descriptors)")
      .def("local_segments", &localSegmentsOf, "The local segment map (LocalSegments)")
      .def("segment_points", &segmentPoints, py::arg("id"),
           "The described observation's points of local segment `id` (ENRICHED_POINT_DTYPE, a "
           "copy); IndexError for an id not in the local segment map");
  m.def(
      "enrich_frame",
      [](const Frame& f, const SensorRig& rig, const EnrichmentConfig& c) {
        EnrichedCloud cloud;
        {
          py::gil_scoped_release release;
          cloud = enrichFrame(f, rig, c);
        }
        return cloudArray(std::move(cloud));
      },
      py::arg("frame"), py::arg("rig"), py::arg("config") = EnrichmentConfig{},
      "Colour and class of the camera pixels on each point (LiDAR frame), ENRICHED_POINT_DTYPE");
}

void bindMapping(py::module_& m) {
  py::class_<MappingResult> mapping(m, "MappingRun", "A target map built from a run");
  defRepr(mapping, "MappingRun", {"segments", "duplicates_removed", "map", "stats"});
  mapping.def_readonly("map", &MappingResult::map)
      .def_property_readonly(
          "trajectory", [](const MappingResult& r) { return posesArray(r.trajectory); },
          "(N, 4, 4): the poses the map was built with")
      .def_readonly("segments", &MappingResult::segments, "finished, before removing duplicates")
      .def_readonly("duplicates_removed", &MappingResult::duplicates_removed)
      .def_readonly("stats", &MappingResult::stats);
  py::class_<MappingSession>(m, "MappingSession", "Builds a target map frame by frame")
      .def(py::init([](const PipelineConfig& c, const DatasetInfo& info,
                       std::shared_ptr<Describer> d, const py::object& poses,
                       const py::object& stages) {
             const FrontEndStages s = stagesOf(stages);
             return std::make_unique<MappingSession>(c, info,
                                                     posesFor(poses, infoWithStages(info, s)),
                                                     required(std::move(d), "MappingSession"), s);
           }),
           py::arg("config"), py::arg("info"), py::arg("describer"), py::arg("poses") = py::none(),
           py::arg("stages") = py::none())
      .def(
          "process",
          [](MappingSession& s, const Frame& f) {
            py::gil_scoped_release release;
            s.process(f);
          },
          py::arg("frame"))
      .def(
          "finish",
          [](MappingSession& s) {
            py::gil_scoped_release release;
            return resultOf(s.finish());
          },
          "The map, once after the last frame");
  m.def(
      "run_mapping",
      [](FrameSource& source, const PipelineConfig& c, std::shared_ptr<Describer> d,
         const py::object& poses, size_t max_frames, const StopFlag* stop) {
        const PoseSource p = posesFor(poses, source.info());
        d = required(std::move(d), "run_mapping");
        RunOptions options;
        options.max_frames = max_frames;
        RunStop stopping(stop);
        stopping.install(options);
        std::optional<MappingResult> result;
        {
          py::gil_scoped_release release;
          result = resultOf(runMapping(source, c, p, std::move(d), options));
        }
        stopping.rethrow();
        return std::move(*result);
      },
      py::arg("dataset"), py::arg("config"), py::arg("describer"), py::arg("poses") = py::none(),
      py::arg("max_frames") = 0, py::arg("stop") = py::none(),
      "Maps the first max_frames frames (0: all), as `semsegmap map` does; a set StopFlag or "
      "Ctrl-C ends it between frames (Ctrl-C then raises KeyboardInterrupt)");
}

// A record's error against ground truth; None without it (a 0.0 would read as perfect).
py::object errorOf(const LocalizationRecord& l, double LocalizationRecord::*error) {
  return l.T_world_base ? py::cast(l.*error) : py::none();
}

void bindLocalizationRecord(py::module_& m) {
  py::class_<LocalizationRecord> record(m, "LocalizationRecord", "One localization of a run");
  defRepr(record, "LocalizationRecord",
          {"frame_index", "frame_number", "timestamp_s", "inliers", "translation_error_m",
           "rotation_error_deg"});
  record.def_readonly("frame_index", &LocalizationRecord::frame_index, "in the run, from 0")
      .def_readonly("frame_number", &LocalizationRecord::frame_number,
                    "the dataset's own number of the frame (its scan's name), or None")
      .def_readonly("timestamp_s", &LocalizationRecord::timestamp_s,
                    "the data's time of the frame, or None when the data has none")
      .def_property_readonly("T_map_base",
                             [](const LocalizationRecord& l) { return poseArray(l.T_map_base); })
      .def_readonly("inliers", &LocalizationRecord::inliers)
      .def_readonly("candidates", &LocalizationRecord::candidates)
      .def_property_readonly("T_world_base",
                             [](const LocalizationRecord& l) -> py::object {
                               if (!l.T_world_base) return py::none();
                               return poseArray(*l.T_world_base);
                             })
      .def_property_readonly(
          "translation_error_m",
          [](const LocalizationRecord& l) {
            return errorOf(l, &LocalizationRecord::translation_error_m);
          },
          "against ground truth, or None without it")
      .def_property_readonly(
          "rotation_error_deg",
          [](const LocalizationRecord& l) {
            return errorOf(l, &LocalizationRecord::rotation_error_deg);
          },
          "against ground truth, or None without it")
      .def_property_readonly(
          "matches",
          [](const LocalizationRecord& l) {
            py::array_t<float> a({l.matches.size(), size_t{2}, size_t{3}});
            auto r = a.mutable_unchecked<3>();
            for (size_t i = 0; i < l.matches.size(); ++i)
              for (int j = 0; j < 3; ++j) {
                r(i, 0, j) = l.matches[i].first[j];
                r(i, 1, j) = l.matches[i].second[j];
              }
            return a;
          },
          "(K, 2, 3) float32: the local centroid carried into the map, the target's")
      .def_readonly("refined", &LocalizationRecord::refined)
      .def_readonly("refinement_correction_m", &LocalizationRecord::refinement_correction_m)
      .def_property_readonly(
          "path", [](const LocalizationRecord& r) { return localizationPathName(r.path); },
          "which segments localized: 'local-map', 'latest-scan' (latest_scan_fallback_m), "
          "'relocalization' (localization.relocalization) or 'scan-context' (a relocalization "
          "from the pose the map's nearest scan context proposed)")
      .def_readonly(
          "registration_fitness", &LocalizationRecord::registration_fitness,
          "the registration check's share of local points on the map's (a relocalization, or "
          "any pose while lost); None otherwise")
      .def_property_readonly(
          "covariance",
          [](const LocalizationRecord& r) {
            py::array_t<double> a({size_t{6}, size_t{6}});
            auto v = a.mutable_unchecked<2>();
            for (py::ssize_t i = 0; i < 6; ++i)
              for (py::ssize_t j = 0; j < 6; ++j) v(i, j) = r.covariance(i, j);
            return a;
          },
          "(6, 6) float64: the pose's covariance from its own evidence, in the map frame, ROS "
          "order (x, y, z, roll, pitch, yaw; m^2, rad^2)")
      .def_property_readonly(
          "status",
          [](const LocalizationRecord& r) { return r.ambiguous ? "ambiguous" : "localized"; },
          "'localized', or 'ambiguous': the scan fits another place as well (never a pose to "
          "use; not among a run's localizations)");
}

void bindLocalizationResults(py::module_& m) {
  bindLocalizationRecord(m);
  py::class_<LocalizationSummary> summary(
      m, "LocalizationSummary",
      "Counts and mean errors of a run's localizations; an error or count that ground truth did "
      "not measure is None");
  defRepr(summary, "LocalizationSummary",
          {"localizations", "with_ground_truth", "below_1m", "below_5m", "mean_translation_error_m",
           "mean_rotation_error_deg"});
  summary.def_readonly("localizations", &LocalizationSummary::localizations)
      .def_readonly("with_ground_truth", &LocalizationSummary::with_ground_truth)
      .def_readonly("below_1m", &LocalizationSummary::below_1m)
      .def_readonly("below_5m", &LocalizationSummary::below_5m)
      .def_readonly("mean_translation_error_m", &LocalizationSummary::mean_translation_error_m)
      .def_readonly("mean_rotation_error_deg", &LocalizationSummary::mean_rotation_error_deg);
  py::class_<LocalizationRun> run(m, "LocalizationRun", "A run localized against a target map");
  run.def("__repr__", [](const LocalizationRun& r) {
    char text[160];
    std::snprintf(text, sizeof(text),
                  "LocalizationRun(frames=%zu, localizations=%zu, distance_m=%.4g, "
                  "has_ground_truth=%s)",
                  r.stats.frames, r.localizations.size(), r.distance_m,
                  r.trajectory_gt.empty() ? "False" : "True");
    return std::string(text);
  });
  run.def_readonly("localizations", &LocalizationRun::localizations)
      .def_property_readonly("trajectory_gt",
                             [](const LocalizationRun& r) { return posesArray(r.trajectory_gt); })
      .def_property_readonly("trajectory_odom",
                             [](const LocalizationRun& r) { return posesArray(r.trajectory_odom); })
      .def_readonly("distance_m", &LocalizationRun::distance_m)
      .def_readonly("odometry_is_ground_truth", &LocalizationRun::odometry_is_ground_truth)
      .def_readonly("stats", &LocalizationRun::stats)
      .def(
          "summary", [](const LocalizationRun& r) { return summarize(r); },
          "summarize(localizations), with the counts None too when the run had no ground truth");
  m.def("summarize",
        static_cast<LocalizationSummary (*)(const std::vector<LocalizationRecord>&)>(&summarize),
        py::arg("records"));
}

// (x, y) or (x, y, radius_m), as localize --prior X,Y[,RADIUS].
std::optional<RelocalizationPrior> priorFrom(const py::object& prior) {
  if (prior.is_none()) return std::nullopt;
  const auto v = prior.cast<std::vector<double>>();
  if ((v.size() != 2 && v.size() != 3) || (v.size() == 3 && !(v[2] > 0)))
    throw py::value_error("prior: expected (x, y) or (x, y, radius_m) with radius_m > 0");
  RelocalizationPrior p;
  p.position = Eigen::Vector3d(v[0], v[1], 0.0);
  if (v.size() == 3) p.radius_m = v[2];
  return p;
}

py::object relocalizeOne(const LocalizationSession& s, const Frame& f, const py::object& prior) {
  const std::optional<RelocalizationPrior> p = priorFrom(prior);
  std::optional<LocalizationRecord> r;
  {
    py::gil_scoped_release release;
    r = s.relocalize(f, p);
  }
  return r ? py::cast(std::move(*r)) : py::none();
}

void bindLocalization(py::module_& m) {
  bindLocalizationResults(m);
  py::class_<LocalizationSession>(m, "LocalizationSession",
                                  "Localizes a run frame by frame, on its odometry")
      .def(py::init([](const PipelineConfig& c, const DatasetInfo& info,
                       std::shared_ptr<TargetMap> map, std::shared_ptr<Describer> d,
                       bool allow_config_mismatch, const py::object& stages) {
             d = required(std::move(d), "LocalizationSession");
             const FrontEndStages s = stagesOf(stages);
             py::gil_scoped_release release;  // builds the map's descriptor index
             return std::make_unique<LocalizationSession>(
                 c, info, std::shared_ptr<const TargetMap>(std::move(map)), std::move(d),
                 settingsCheck(allow_config_mismatch), s);
           }),
           py::arg("config"), py::arg("info"), py::arg("map"), py::arg("describer"),
           py::arg("allow_config_mismatch") = false, py::arg("stages") = py::none(),
           "RuntimeError when the map's descriptors are not the describer's, or when the map "
           "was built with other settings than `config` (unless allow_config_mismatch: then "
           "a warning on stderr for each)")
      .def(
          "process",
          [](LocalizationSession& s, const Frame& f) -> py::object {
            std::optional<LocalizationRecord> found;
            {
              py::gil_scoped_release release;
              found = s.process(f);
            }
            return found ? py::cast(std::move(*found)) : py::none();
          },
          py::arg("frame"), "The LocalizationRecord this frame gave, or None")
      .def(
          "relocalize",
          [](const LocalizationSession& s, const Frame& f, const py::object& prior) {
            return relocalizeOne(s, f, prior);
          },
          py::arg("frame"), py::kw_only(), py::arg("prior") = py::none(),
          "One scan on its own, as a robot that wakes up has it (the command line's first frame "
          "with localize --relocalize, whatever the config's localization.relocalization "
          "says); the session's run is untouched. prior: (x, y) or (x, y, radius_m) in the "
          "map frame, radius 50 m. The LocalizationRecord (its T_map_base is the pose), or "
          "None")
      .def(
          "relocalize",
          [](const LocalizationSession& s,
             const py::array_t<float, py::array::c_style | py::array::forcecast>& points,
             const py::object& images, const py::object& label_images, const py::object& prior) {
            const Frame f = frameFrom(points, py::none(), py::none(), images, label_images,
                                      py::none(), py::none(), 0, 0.0);
            return relocalizeOne(s, f, prior);
          },
          py::arg("points"), py::arg("images") = py::none(), py::kw_only(),
          py::arg("label_images") = py::none(), py::arg("prior") = py::none(),
          "The same for a scan given as arrays, as Frame(points, images=..., "
          "label_images=...) takes them: the pose of the LiDAR's base in the map")
      .def_property_readonly(
          "run", [](const LocalizationSession& s) { return LocalizationRun(s.run()); },
          "the run so far (a copy)");
  m.def(
      "run_localization",
      [](FrameSource& source, const PipelineConfig& c, std::shared_ptr<TargetMap> map,
         std::shared_ptr<Describer> d, size_t max_frames, bool allow_config_mismatch,
         const StopFlag* stop) {
        d = required(std::move(d), "run_localization");
        RunOptions options;
        options.max_frames = max_frames;
        RunStop stopping(stop);
        stopping.install(options);
        std::optional<LocalizationRun> run;
        {
          py::gil_scoped_release release;
          run = runLocalization(source, c, std::shared_ptr<const TargetMap>(std::move(map)),
                                std::move(d), options, settingsCheck(allow_config_mismatch));
        }
        stopping.rethrow();
        return std::move(*run);
      },
      py::arg("dataset"), py::arg("config"), py::arg("map"), py::arg("describer"),
      py::arg("max_frames") = 0, py::arg("allow_config_mismatch") = false,
      py::arg("stop") = py::none(),
      "Localizes the first max_frames frames (0: all), as `semsegmap localize` does; a set "
      "StopFlag or Ctrl-C ends it between frames (Ctrl-C then raises KeyboardInterrupt)");
}

}  // namespace

void bindPipeline(py::module_& m) {
  bindResults(m);
  bindPipelineClass(m);
  bindMapping(m);
  bindLocalization(m);
}

}  // namespace semsegmap::python
