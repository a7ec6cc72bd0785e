// The pipeline configuration (pipeline/pipeline_config.h and the stages' config structs) and its
// YAML reader (settings/config.h). Fields are named as in the C++ structs, and a setting's YAML key
// is its attribute path (pipeline/setting_table.h; python/tests/test_config.py holds the fields
// bound here to the table: localization.localizer.index.k is c.localization.localizer.index.k).
#include "bindings.h"
#include "semsegmap/pipeline/pipeline_config.h"
#include "semsegmap/pipeline/setting_table.h"
#include "semsegmap/settings/config.h"

namespace semsegmap::python {

namespace {

void bindFrontEndConfigs(py::module_& m) {
  StructBinding<EnrichmentConfig>(m, "EnrichmentConfig", "enrich/enricher.h")
      .field("occlusion_radius_px", &EnrichmentConfig::occlusion_radius_px)
      .field("occlusion_tolerance_m", &EnrichmentConfig::occlusion_tolerance_m)
      .field("occlusion_tolerance_rel", &EnrichmentConfig::occlusion_tolerance_rel);

  py::enum_<DynamicRemoval>(m, "DynamicRemoval", "How dynamic points leave the local map")
      .value("point", DynamicRemoval::kPoint)
      .value("voxel", DynamicRemoval::kVoxel);
  StructBinding<GroundRemovalConfig>(m, "GroundRemovalConfig", "local_map/ground_removal.h")
      .field("cell_size_m", &GroundRemovalConfig::cell_size_m)
      .field("neighbourhood_cells", &GroundRemovalConfig::neighbourhood_cells)
      .field("height_above_m", &GroundRemovalConfig::height_above_m);
  StructBinding<LocalMapConfig>(m, "LocalMapConfig", "local_map/local_map.h")
      .field("voxel_size_m", &LocalMapConfig::voxel_size_m)
      .field("radius_m", &LocalMapConfig::radius_m)
      .field("min_points_per_voxel", &LocalMapConfig::min_points_per_voxel)
      .field("remove_dynamic_classes", &LocalMapConfig::remove_dynamic_classes)
      .field("dynamic_removal", &LocalMapConfig::dynamic_removal)
      .field("dynamic_vote_share", &LocalMapConfig::dynamic_vote_share)
      .field("remove_ground_classes", &LocalMapConfig::remove_ground_classes)
      .field("remove_unknown_class", &LocalMapConfig::remove_unknown_class)
      .field("remove_unobserved", &LocalMapConfig::remove_unobserved)
      .field("geometric_ground_removal", &LocalMapConfig::geometric_ground_removal)
      .field("ground", &LocalMapConfig::ground);

  StructBinding<SegmentationConfig>(m, "SegmentationConfig", "segment/semantic_distance.h")
      .field("d_segment_m", &SegmentationConfig::d_segment_m)
      .field("hue_threshold", &SegmentationConfig::hue_threshold)
      .field("hue_penalty", &SegmentationConfig::hue_penalty)
      .field("class_penalty", &SegmentationConfig::class_penalty)
      .field("min_segment_points", &SegmentationConfig::min_segment_points)
      .field("max_segment_points", &SegmentationConfig::max_segment_points)
      .field("observation_growth", &SegmentationConfig::observation_growth)
      .field("keep_all_observation_points", &SegmentationConfig::keep_all_observation_points);

  StructBinding<DescriptorConfig>(m, "DescriptorConfig", "pipeline/pipeline_config.h")
      .field("kind", &DescriptorConfig::kind,
             "eigen | fpfh | segmap-cnn | semsegmap-net | 3dsmoothnet")
      .field("model", &DescriptorConfig::model, "model file of a learned descriptor")
      .field("model_lidar_only", &DescriptorConfig::model_lidar_only,
             "the model taken instead for input with neither colour nor classes")
      .field("batch", &DescriptorConfig::batch, "segments described per forward pass")
      .field("keypoints", &DescriptorConfig::keypoints,
             "3dsmoothnet: keypoints a segment is described at, 0: the model's");
}

void bindLocalizationConfigs(py::module_& m) {
  StructBinding<DescriptorIndexConfig>(m, "DescriptorIndexConfig", "localize/descriptor_index.h")
      .field("k", &DescriptorIndexConfig::k)
      .field("exact_below", &DescriptorIndexConfig::exact_below)
      .field("ivf_lists", &DescriptorIndexConfig::ivf_lists)
      .field("ivf_probes", &DescriptorIndexConfig::ivf_probes)
      .field("ivf_training_iterations", &DescriptorIndexConfig::ivf_training_iterations);
  using GV = GeometricVerificationConfig;
  StructBinding<GV>(m, "GeometricVerificationConfig", "localize/geometric_verification.h")
      .field("resolution_m", &GV::resolution_m)
      .field("min_inliers", &GV::min_inliers)
      .field("refine", &GV::refine)
      .field("inlier_tolerance_m", &GV::inlier_tolerance_m)
      .field("min_spread_m", &GV::min_spread_m)
      .field("max_search_nodes", &GV::max_search_nodes);
  StructBinding<LocalizerConfig>(m, "LocalizerConfig", "localize/localizer.h")
      .field("index", &LocalizerConfig::index)
      .field("verification", &LocalizerConfig::verification)
      .field("min_local_segments", &LocalizerConfig::min_local_segments);
  StructBinding<RefinementConfig>(m, "RefinementConfig", "localize/pose_refinement.h")
      .field("enabled", &RefinementConfig::enabled)
      .field("max_points_per_segment", &RefinementConfig::max_points_per_segment)
      .field("coarse_distance_m", &RefinementConfig::coarse_distance_m)
      .field("fine_distance_m", &RefinementConfig::fine_distance_m)
      .field("kernel_scale_m", &RefinementConfig::kernel_scale_m)
      .field("max_correction_m", &RefinementConfig::max_correction_m)
      .field("min_correspondences", &RefinementConfig::min_correspondences)
      .field("neighbours_m", &RefinementConfig::neighbours_m);
  using RC = RegistrationCheckConfig;
  StructBinding<RC>(m, "RegistrationCheckConfig", "localize/registration_check.h")
      .field("max_points_per_segment", &RC::max_points_per_segment)
      .field("coarse_distance_m", &RC::coarse_distance_m)
      .field("retry_coarse_distance_m", &RC::retry_coarse_distance_m)
      .field("fine_distance_m", &RC::fine_distance_m)
      .field("kernel_scale_m", &RC::kernel_scale_m)
      .field("near_m", &RC::near_m)
      .field("min_fitness", &RC::min_fitness)
      .field("min_points", &RC::min_points)
      .field("max_correction_m", &RC::max_correction_m)
      .field("max_correction_deg", &RC::max_correction_deg)
      .field("max_tilt_deg", &RC::max_tilt_deg)
      .field("place_radius_m", &RC::place_radius_m);
  using RL = RelocalizationConfig;
  StructBinding<RL>(m, "RelocalizationConfig", "localize/relocalizer.h")
      .field("enabled", &RL::enabled)
      .field("after_m", &RL::after_m)
      .field("jump_m", &RL::jump_m)
      .field("jump_deg", &RL::jump_deg)
      .field("k", &RL::k)
      .field("k_in_place", &RL::k_in_place)
      .field("place_radius_m", &RL::place_radius_m)
      .field("cell_m", &RL::cell_m)
      .field("max_places", &RL::max_places)
      .field("min_votes", &RL::min_votes)
      .field("verification", &RL::verification)
      .field("check", &RL::check)
      .field("scan_context", &RL::scan_context)
      .field("scan_context_max_distance", &RL::scan_context_max_distance)
      .field("scan_context_candidates", &RL::scan_context_candidates)
      .field("scan_context_min_fitness", &RL::scan_context_min_fitness)
      .field("scan_context_distinct_ratio", &RL::scan_context_distinct_ratio)
      .field("ambiguity_ratio", &RL::ambiguity_ratio);
  using PC = PoseCovarianceConfig;
  StructBinding<PC>(m, "PoseCovarianceConfig", "localize/pose_covariance.h")
      .field("registration_inflation", &PC::registration_inflation)
      .field("centroid_inflation", &PC::centroid_inflation)
      .field("min_sigma_m", &PC::min_sigma_m)
      .field("min_sigma_deg", &PC::min_sigma_deg)
      .field("max_sigma_m", &PC::max_sigma_m)
      .field("max_sigma_deg", &PC::max_sigma_deg)
      .field("degeneracy_ratio", &PC::degeneracy_ratio);
  StructBinding<LocalizationConfig>(m, "LocalizationConfig", "pipeline/pipeline_config.h")
      .field("localizer", &LocalizationConfig::localizer)
      .field("every_n_frames", &LocalizationConfig::every_n_frames)
      .field("latest_scan_fallback_m", &LocalizationConfig::latest_scan_fallback_m)
      .field("refinement", &LocalizationConfig::refinement)
      .field("relocalization", &LocalizationConfig::relocalization)
      .field("covariance", &LocalizationConfig::covariance);
  using TMB = TargetMapBuilderConfig;
  StructBinding<TMB>(m, "TargetMapBuilderConfig", "localize/target_map.h")
      .field("duplicate_distance_m", &TMB::duplicate_distance_m)
      .field("max_points_per_segment", &TMB::max_points_per_segment)
      .field("earlier_observations_apart_m", &TMB::earlier_observations_apart_m)
      .field("scan_context_apart_m", &TMB::scan_context_apart_m);
  StructBinding<PoseGraphConfig>(m, "PoseGraphConfig", "graph/pose_graph.h")
      .field("odometry_translation_sigma_m", &PoseGraphConfig::odometry_translation_sigma_m)
      .field("odometry_rotation_sigma_rad", &PoseGraphConfig::odometry_rotation_sigma_rad)
      .field("loop_translation_sigma_m", &PoseGraphConfig::loop_translation_sigma_m)
      .field("loop_rotation_sigma_rad", &PoseGraphConfig::loop_rotation_sigma_rad)
      .field("loop_robust_scale", &PoseGraphConfig::loop_robust_scale)
      .field("max_iterations", &PoseGraphConfig::max_iterations)
      .field("threads", &PoseGraphConfig::threads);
  StructBinding<LoopClosureConfig>(m, "LoopClosureConfig", "pipeline/pipeline_config.h")
      .field("exclude_recent_m", &LoopClosureConfig::exclude_recent_m)
      .field("min_travel_between_loops_m", &LoopClosureConfig::min_travel_between_loops_m)
      .field("graph", &LoopClosureConfig::graph);
  StructBinding<SessionMergeConfig>(m, "SessionMergeConfig", "pipeline/pipeline_config.h")
      .field("same_segment_m", &SessionMergeConfig::same_segment_m)
      .field("min_localizations", &SessionMergeConfig::min_localizations);
}

const char* kindName(SettingKind kind) {
  switch (kind) {
    case SettingKind::kFlag:
      return "flag";
    case SettingKind::kCount:
      return "count";
    case SettingKind::kNumber:
      return "number";
    case SettingKind::kText:
      return "text";
    case SettingKind::kChoice:
      return "choice";
    case SettingKind::kTriple:
      return "triple";
  }
  return "";
}

// The setting table as dicts, for a program that lists or checks settings.
py::list settingTableList() {
  py::list out;
  for (const Setting& s : settingTable()) {
    py::dict d;
    d["key"] = s.key;
    d["kind"] = kindName(s.kind);
    if (s.kind == SettingKind::kCount) d["limits"] = py::make_tuple(s.lo, s.hi);
    if (s.kind == SettingKind::kChoice) d["choices"] = s.choices;
    d["recorded"] = s.recorded;
    d["default"] = settingText(s.get(Settings{}));
    d["description"] = s.description;
    out.append(d);
  }
  return out;
}

}  // namespace

void bindConfig(py::module_& m) {
  bindFrontEndConfigs(m);
  bindLocalizationConfigs(m);
  StructBinding<PipelineConfig>(m, "PipelineConfig", "The whole pipeline's configuration")
      .field("enrichment", &PipelineConfig::enrichment)
      .field("local_map", &PipelineConfig::local_map)
      .field("segmentation", &PipelineConfig::segmentation)
      .field("descriptor", &PipelineConfig::descriptor)
      .field("localization", &PipelineConfig::localization)
      .field("target_map", &PipelineConfig::target_map)
      .field("loop_closure", &PipelineConfig::loop_closure)
      .field("session_merge", &PipelineConfig::session_merge);
  m.def(
      "load_config", [](const std::filesystem::path& path) { return loadPipelineConfig(path); },
      py::arg("path"),
      "Reads a YAML config (config/*.yaml) as the command line does: descriptor.model relative "
      "to the file; an unknown key, a wrong type or a bad value raises RuntimeError "
      "'<file>: <section.key>: <what>'.");
  m.def("setting_table", &settingTableList,
        "Every setting of a config file: key (its YAML key and attribute path; odometry.* and "
        "semantics.* are read by the datasets), kind, limits or choices, whether a map records "
        "it, its default as text and a description.");
}

}  // namespace semsegmap::python
