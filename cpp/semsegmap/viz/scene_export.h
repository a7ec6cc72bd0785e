// What `semsegmap view` draws, as the JSON its page reads (viewer/README.md has the layout): a
// target map's segments (their stored points, else centroids sized by point count) and the
// sessions it was merged from (each one's name, entries and trajectory), a localization run
// (every localization with its pose, inliers, error and matched segment pairs; the ground-truth
// trajectory and the estimated one), a SLAM run (trajectory, odometry, loop closures) and a
// segmentation run (every segment's points). Positions are relative to an origin near the map's
// centre, so that the page's 32-bit floats keep millimetres far from zero; the bulk arrays are
// base64 of little-endian binary, points as 16-bit offsets from their segment's centroid (like
// the map file's float16 ones), which keeps 100k segments to a few megabytes.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "semsegmap/core/class_table.h"
#include "semsegmap/core/json.h"
#include "semsegmap/localize/target_map.h"
#include "semsegmap/outputs/localization_details.h"
#include "semsegmap/outputs/run_folders.h"

namespace semsegmap::viz {

constexpr int kSceneVersion = 2;  // 2: the map's sessions
// Where the page's template (the viewer's bundle) takes the scene.
constexpr std::string_view kScenePlaceholder = "@SEMSEGMAP_SCENE@";

struct SceneInputs {
  std::string title;
  std::string map_name;                              // shown; the map's file, say
  const TargetMap* map = nullptr;                    // required
  const LocalizationFolder* localization = nullptr;  // each of these optional
  const SlamFolder* slam = nullptr;
  const SegmentFolder* segments = nullptr;
  ClassTable classes = ClassTable::Default();  // the map stores class ids only
  std::string colouring = "class";             // how the page starts: class, segment or session
};

nlohmann::ordered_json sceneJson(const SceneInputs& in);

// The page: `page_template` with the scene's JSON at kScenePlaceholder, escaped so that nothing
// in it can end the <script> element that holds it. Throws std::runtime_error when the template
// has no placeholder (a broken build of viewer/).
std::string viewerPage(std::string_view page_template, const nlohmann::ordered_json& scene);

}  // namespace semsegmap::viz
