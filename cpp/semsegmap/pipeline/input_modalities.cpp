#include "semsegmap/pipeline/input_modalities.h"

namespace semsegmap {

InputModalities inputModalitiesOf(const DatasetInfo& info) {
  InputModalities m;
  m.color = !info.rig.cameras.empty();
  m.classes = m.color || (info.has_point_labels && info.point_labels_have_classes);
  return m;
}

std::string modalitiesText(const InputModalities& m) {
  if (m.color && m.classes) return "colour and classes";
  if (m.color) return "colour, no classes";
  if (m.classes) return "classes, no colour";
  return "geometry only";
}

DescriptorChoice chooseDescriptor(const DescriptorConfig& descriptor,
                                  const InputModalities& input) {
  DescriptorChoice out{descriptor, ""};
  // Only semsegmap-net sees colour and classes; segmap-cnn and the hand-made ones see geometry.
  if (descriptor.kind != "semsegmap-net" || input.color || input.classes) return out;
  if (!descriptor.model_lidar_only.empty()) {
    out.descriptor.model = descriptor.model_lidar_only;
    out.note = "the input has no colour and no classes: descriptor model " +
               descriptor.model_lidar_only + " (descriptor.model_lidar_only) instead of " +
               descriptor.model;
  } else {
    out.note =
        "the input has no colour and no classes, and the configuration names no "
        "descriptor.model_lidar_only: " +
        descriptor.model +
        " describes geometry alone (a colour model sees every point grey and of class unknown)";
  }
  return out;
}

}  // namespace semsegmap
