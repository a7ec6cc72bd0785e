// The page of `semsegmap view` (viewer/: three.js bundled by esbuild at build time), compiled
// into the binary so that the command needs no file beside it and the pages it writes need no
// network. Only in a build with the viewer (SEMSEGMAP_WITH_VIEWER, cmake/SemsegmapViewer.cmake).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace semsegmap::app {

// The HTML with viz::kScenePlaceholder where a scene goes (generated: viewer_asset.cpp).
std::string_view viewerPageTemplate();

// What a page shows: a map and, each optional, the folders of runs about it.
struct ViewSources {
  std::filesystem::path map;
  std::optional<std::filesystem::path> localization, slam, segments;
  std::string colouring = "class";
  std::string title;  // empty: made from the map's and the runs' names
};

// Reads every source (each failure a one-line error naming the file), writes the page to `out`
// through a temporary name and returns its size in bytes. cmd_view.cpp.
uint64_t writeViewPage(const ViewSources& sources, const std::filesystem::path& out);

}  // namespace semsegmap::app
