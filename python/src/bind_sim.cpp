// sim/: the built-in simulator as a Dataset whose frames are rendered on demand, with the keys of
// the sim: dataset spec (datasets/open_dataset.h) as keywords. Only in a build with the simulator.
#include "bindings.h"
#include "semsegmap/core/frame_source.h"

#if SEMSEGMAP_WITH_SIM
#include "semsegmap/sim/simulator.h"
#endif

namespace semsegmap::python {

#if SEMSEGMAP_WITH_SIM

namespace {

std::shared_ptr<sim::Simulator> makeSimulator(uint64_t world, const std::string& run,
                                              const std::string& preset,
                                              const std::string& condition,
                                              const std::optional<uint64_t>& traffic, size_t frames,
                                              bool cameras, bool sweep, int label_noise,
                                              const std::optional<SensorRig>& rig) {
  sim::SimConfig config;
  config.run = sim::parseRun(run);
  config.condition = condition;
  config.traffic_seed = traffic;
  config.max_frames = frames;
  config.render_cameras = cameras;
  config.lidar_sweep = sweep;
  config.label_noise = label_noise;
  if (rig) config.rig = *rig;
  config.world = sim::worldPreset(preset, world);
  py::gil_scoped_release release;  // generates the world and its ray tracing scene
  return std::make_shared<sim::Simulator>(config);
}

}  // namespace

void bindSim(py::module_& m) {
  py::class_<sim::Simulator, FrameSource, std::shared_ptr<sim::Simulator>>(
      m, "Simulator",
      "The built-in simulator (sim/simulator.h): a Dataset whose frames are rendered when read. "
      "The keywords are those of the sim: dataset spec.")
      .def(py::init(&makeSimulator), py::kw_only(), py::arg("world") = 1, py::arg("run") = "S2",
           py::arg("preset") = "full", py::arg("condition") = "", py::arg("traffic") = py::none(),
           py::arg("frames") = 0, py::arg("cameras") = true, py::arg("sweep") = false,
           py::arg("label_noise") = 0, py::arg("rig") = py::none(),
           "world: seed; run: S0..S3; preset: full | small | tiny; condition: '' (the run's) or "
           "a lighting; traffic: seed (None: the run's); frames: at most (0: the whole run); "
           "cameras: render them; sweep: motion distortion; label_noise: 0..3; rig: SensorRig "
           "(None: default_sim_rig())")
      .def_property_readonly("traffic_seed", &sim::Simulator::trafficSeed)
      .def_property_readonly(
          "trajectory_world",
          [](const sim::Simulator& s) { return posesArray(s.trajectory().T_world_base); },
          "(N, 4, 4): the run's ground-truth poses of the base")
      .def_property_readonly(
          "trajectory_odom",
          [](const sim::Simulator& s) { return posesArray(s.trajectory().T_odom_base); },
          "(N, 4, 4): its drifting odometry")
      .def_property_readonly("length_m",
                             [](const sim::Simulator& s) { return s.trajectory().length_m; });
}

#else

void bindSim(py::module_&) {}  // semsegmap.WITH_SIM is False

#endif

}  // namespace semsegmap::python
