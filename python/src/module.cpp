// The module semsegmap._semsegmap, imported by the package semsegmap (python/semsegmap/).
//
// Errors keep the library's one-line messages; pybind11 maps std::invalid_argument to
// ValueError, std::out_of_range to IndexError and every other std::exception to RuntimeError.
// File errors are RuntimeError throughout: the library reports a missing, unreadable or corrupt
// file as a std::runtime_error naming it, and a stray std::filesystem error takes the same way
// rather than becoming the one OSError among them.
#include "bindings.h"
#include "semsegmap/core/diagnostics.h"

namespace semsegmap::python {

namespace {

// What this build has (the SEMSEGMAP_WITH_* compile definitions of the libraries): tests and
// users skip the rest.
void buildFlags(py::module_& m) {
  m.attr("__version__") = SEMSEGMAP_VERSION;
  m.attr("WITH_SIM") = bool(SEMSEGMAP_WITH_SIM);
  m.attr("WITH_TORCH") = bool(SEMSEGMAP_WITH_TORCH);
  m.attr("WITH_PCL") = bool(SEMSEGMAP_WITH_PCL);
  m.attr("WITH_ROS") = bool(SEMSEGMAP_WITH_ROS);
}

}  // namespace

}  // namespace semsegmap::python

PYBIND11_MODULE(_semsegmap, m) {
  using namespace semsegmap::python;
  m.doc() = "Segment-based semantic localization (SemSegMap): the C++ library's bindings";
  buildFlags(m);
  // The library's messages name options as the keyword arguments a Python user gives
  // (odometry=FILE), not as the command line's --odometry FILE.
  semsegmap::setOptionSpelling(semsegmap::OptionSpelling::kKeyword);
  // In dependency order: a class is registered before any signature that names it.
  bindCore(m);
  bindConfig(m);
  bindDatasets(m);
  bindDescribe(m);
  bindLocalize(m);
  bindPipeline(m);
  bindLive(m);
  bindSim(m);
}
