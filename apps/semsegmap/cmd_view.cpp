// semsegmap view: one self-contained HTML file to look at a target map, and a localization,
// SLAM or segmentation run about it, in 3D in any browser, offline (viewer/README.md).
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "cli_args.h"
#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/diagnostics.h"
#include "semsegmap/store/map_location.h"
#include "semsegmap/viz/scene_export.h"
#include "viewer_asset.h"

namespace semsegmap::app {

namespace {

// "tiny.map · S2 (sim:...)": what the page's title says when none is given.
std::string titleOf(const ViewSources& s, const LocalizationFolder* localization) {
  std::string title = mapDisplayName(s.map.string());
  if (localization)
    title += " · " + (localization->dataset.empty() ? localization->dir.filename().string()
                                                    : localization->dataset);
  return title;
}

std::optional<std::filesystem::path> optionalPath(const CliArgs& a, const std::string& name) {
  if (!a.has(name)) return std::nullopt;
  return std::filesystem::path(a.get(name));
}

int runView(const CliArgs& a) {
  const auto start = std::chrono::steady_clock::now();
  ViewSources sources;
  sources.map = a.get("map");
  sources.localization = optionalPath(a, "localization");
  sources.slam = optionalPath(a, "slam");
  sources.segments = optionalPath(a, "segments");
  sources.colouring = a.get("colour");
  if (a.has("title")) sources.title = a.get("title");
  const std::filesystem::path out = a.get("out");
  const uint64_t bytes = writeViewPage(sources, out);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("wrote %s (%.1f MB) in %.1f s: open it in a browser, no network needed\n",
              out.string().c_str(), static_cast<double>(bytes) / 1e6, s);
  return 0;
}

}  // namespace

uint64_t writeViewPage(const ViewSources& s, const std::filesystem::path& out) {
  const TargetMap map = loadMapAt(s.map.string());
  std::optional<LocalizationFolder> localization;
  std::optional<SlamFolder> slam;
  std::optional<SegmentFolder> segments;
  if (s.localization) localization = readLocalizationFolder(*s.localization);
  if (s.slam) slam = readSlamFolder(*s.slam);
  if (s.segments) segments = readSegmentFolder(*s.segments);
  if (localization && !localization->has_matches)
    note(localization->dir.string() +
         " has no matches.csv (written by semsegmap localize since the viewer came): the page "
         "shows no matched segments");
  viz::SceneInputs in;
  in.title = s.title.empty() ? titleOf(s, localization ? &*localization : nullptr) : s.title;
  in.map_name = mapDisplayName(s.map.string());
  in.map = &map;
  in.localization = localization ? &*localization : nullptr;
  in.slam = slam ? &*slam : nullptr;
  in.segments = segments ? &*segments : nullptr;
  in.colouring = s.colouring;
  const std::string page = viz::viewerPage(viewerPageTemplate(), viz::sceneJson(in));
  writeBytesAtomically(out, page);
  return page.size();
}

const CommandSpec& viewCommand() {
  static const CommandSpec command{
      "view",
      "a map and its runs in 3D in the browser -> one self-contained .html (offline)",
      {
          {"map", Value::kText, "MAP", "",
           "the target map: a file, or postgresql://...?map=NAME[&region=X,Y,RADIUS]", kRequired},
          {"localization", Value::kText, "DIR", "",
           "a localization run against it (semsegmap localize, eval, demo)"},
          {"slam", Value::kText, "DIR", "", "a loop-closure run (semsegmap slam)"},
          {"segments", Value::kText, "DIR", "", "a segmentation run (semsegmap segment)"},
          {"colour", Value::kText, "class|segment|session", "class",
           "how the segments are coloured first"},
          {"title", Value::kText, "TEXT", "", "the page's title (default: the map and run names)"},
          {"out", Value::kText, "FILE.html", "", "the page to write", kRequired},
      },
      "The page embeds everything it shows (three.js included) and fetches nothing: copy it\n"
      "anywhere, open it in any current browser. Click a localization to see its matches.\n",
      runView};
  return command;
}

}  // namespace semsegmap::app
