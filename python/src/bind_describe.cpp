// describe/: the four segment describers, made from a config as the command line makes them
// (artefacts/model_file.h makeDescriber; apps/semsegmap/dataset_args.cpp describerFor), describing
// segment points given as numpy arrays.
#include <iostream>

#include "bindings.h"
#include "semsegmap/describe/descriptor.h"
#if SEMSEGMAP_WITH_TORCH
#include "semsegmap/describe/learned_describer.h"
#endif
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/pipeline/input_modalities.h"

namespace semsegmap::python {

namespace {

Eigen::MatrixXf describe(Describer& d, const py::list& segments) {
  std::vector<EnrichedCloud> clouds;
  for (size_t i = 0; i < segments.size(); ++i)
    clouds.push_back(
        enrichedCloudFrom(segments[i].cast<py::array>(), "segments[" + std::to_string(i) + "]"));
  std::vector<DescriptorInput> inputs;
  for (const EnrichedCloud& c : clouds) inputs.push_back({&c});
  py::gil_scoped_release release;
  return d.describe(inputs);
}

std::shared_ptr<Describer> make(const DescriptorConfig& config, int threads) {
  py::gil_scoped_release release;  // a learned model is read from its file
  return makeDescriber(config, threads);
}

// The command line's choice of model for the data (descriptor.model_lidar_only for a LiDAR
// without a camera), with its note on stderr as the command line prints it.
std::shared_ptr<Describer> describerFor(const DescriptorConfig& config, const DatasetInfo& info,
                                        int threads) {
  const DescriptorChoice choice = chooseDescriptor(config, inputModalitiesOf(info));
  if (!choice.note.empty())
    py::print("note: " + choice.note, py::arg("file") = py::module_::import("sys").attr("stderr"));
  return make(choice.descriptor, threads);
}

}  // namespace

void bindDescribe(py::module_& m) {
  py::class_<Describer, std::shared_ptr<Describer>>(
      m, "Describer",
      "A segment describer (describe/descriptor.h). Shared by the pipelines given it, but used "
      "by one at a time.")
      .def_property_readonly("kind", [](const Describer& d) { return descriptorName(d.kind()); })
      .def_property_readonly("dimension", &Describer::dimension)
      .def_property_readonly("fingerprint", &Describer::fingerprint,
                             "the exact model the descriptors come from")
      .def("describe", &describe, py::arg("segments"),
           "One descriptor row per segment, (B, dimension) float32. A segment is an array of "
           "ENRICHED_POINT_DTYPE (map frame, with colour and class), or (K, 3) xyz (no colour, "
           "class unknown). Releases the GIL.");
  m.def("make_describer", &make, py::arg("config"), py::arg("threads") = 0,
        "The describer a DescriptorConfig asks for (kind, and model for the learned kinds); "
        "threads 0: all cores. RuntimeError naming the model file, or saying what this build "
        "lacks.");
  m.def("describer_for", &describerFor, py::arg("config"), py::arg("info"), py::arg("threads") = 0,
        "make_describer with the model that suits the dataset's input, as the map and localize "
        "commands choose it (a note on stderr says what was chosen).");
  m.def(
      "descriptor_not_built",
      [](const std::string& kind) { return descriptorNotBuilt(parseDescriptorKind(kind)); },
      py::arg("kind"), "Why this build cannot describe with `kind`, or '' when it can");
  // Process-wide, so the program's choice (describe/learned_describer.h says why it pays).
  m.def(
      "keep_freed_memory_for_torch",
      [] {
#if SEMSEGMAP_WITH_TORCH
        keepFreedMemoryForTorch();
#endif
      },
      "Once at start-up of a program that describes many segments with a learned descriptor: "
      "glibc's malloc keeps freed activations instead of faulting them back in (40-50 % of "
      "their time). Process-wide, idempotent; a no-op without glibc or libtorch.");
}

}  // namespace semsegmap::python
