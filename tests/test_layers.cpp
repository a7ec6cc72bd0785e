// The layer rule of docs/architecture.md, checked on the sources: every folder of the library
// includes only from the folders below it. In particular the stages never include a file folder
// (io/, settings/, artefacts/, outputs/) or sim/ (the simulator): they take and return plain
// values.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>

namespace {

namespace fs = std::filesystem;

const std::set<std::string> kStages = {"semantics", "enrich", "local_map", "segment",  "describe",
                                       "localize",  "graph",  "odometry",  "pipeline", "learn"};

std::set<std::string> with(std::set<std::string> s, const std::set<std::string>& more) {
  s.insert(more.begin(), more.end());
  return s;
}

// Folder -> the folders it may include from (its own is always allowed).
std::map<std::string, std::set<std::string>> makeTable() {
  const std::set<std::string> stages = {"core",     "semantics", "enrich", "local_map", "segment",
                                        "describe", "localize",  "graph",  "odometry"};
  const std::set<std::string> below_files = with(stages, {"pipeline", "learn", "io"});
  const std::set<std::string> files =
      with(below_files, {"settings", "artefacts", "outputs", "store"});
  const std::set<std::string> below_viz = with(files, {"sim", "datasets"});
  return {
      {"core", {}},
      {"sim", {"core"}},
      {"semantics", {"core"}},
      {"enrich", {"core"}},
      {"local_map", {"core"}},
      {"segment", {"core", "local_map"}},
      {"describe", {"core", "local_map", "segment"}},
      {"localize", {"core", "odometry"}},  // pose refinement registers with its ICP
      {"graph", {"core"}},
      {"odometry", {"core"}},
      {"pipeline", stages},
      {"learn", with(stages, {"pipeline"})},
      // Frame readers, bags and the files they read need nothing above core, so that reading
      // a bag does not link the whole stack.
      {"io", {"core"}},
      {"settings", with(stages, {"pipeline", "io"})},            // config files
      {"artefacts", with(stages, {"pipeline", "learn", "io"})},  // maps, models, caches
      {"outputs", with(stages, {"pipeline", "io"})},             // what a run writes
      // where maps live: files or a PostgreSQL store
      {"store", with(stages, {"pipeline", "learn", "io", "artefacts"})},
      {"datasets", with(files, {"sim"})},
      {"viz", below_viz},
      {"eval", with(below_viz, {"viz"})},
  };
}

const std::map<std::string, std::set<std::string>>& allowed() {
  static const auto table = makeTable();
  return table;
}

struct Violation {
  std::string file, include;
};

// The folder of a `#include "semsegmap/<folder>/..."` line, or "" for any other line. Parsed by
// hand: GCC 12 warns inside <regex> under the sanitizers, and warnings are errors.
std::string includedFolder(const std::string& line) {
  const size_t hash = line.find_first_not_of(" \t");
  if (hash == std::string::npos || line[hash] != '#' ||
      line.find("include", hash) == std::string::npos)
    return "";
  const size_t at = line.find("semsegmap/", hash);
  if (at == std::string::npos || at == 0 || (line[at - 1] != '"' && line[at - 1] != '<')) return "";
  const size_t start = at + 10, end = line.find('/', start);
  return end == std::string::npos ? "" : line.substr(start, end - start);
}

std::vector<Violation> violations(const fs::path& root) {
  std::vector<Violation> out;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    const fs::path& p = entry.path();
    if (p.extension() != ".h" && p.extension() != ".cpp") continue;
    const std::string folder = p.parent_path().filename().string();
    const auto rule = allowed().find(folder);
    if (rule == allowed().end()) {
      out.push_back({p.string(), "(a folder the layer rule does not know)"});
      continue;
    }
    std::ifstream in(p);
    std::string line;
    while (std::getline(in, line)) {
      const std::string included = includedFolder(line);
      if (!included.empty() && included != folder && !rule->second.count(included))
        out.push_back({p.string(), line});
    }
  }
  return out;
}

const fs::path kLibrary = fs::path(SEMSEGMAP_SOURCE_DIR) / "cpp" / "semsegmap";

}  // namespace

TEST(Layers, EveryFolderIncludesOnlyFromTheFoldersBelowIt) {
  for (const Violation& v : violations(kLibrary)) ADD_FAILURE() << v.file << ": " << v.include;
}

TEST(Layers, StagesNeverIncludeIoOrSim) {
  for (const std::string& stage : kStages) {
    const auto& may = allowed().at(stage);
    for (const char* files : {"io", "settings", "artefacts", "outputs", "store", "sim", "datasets"})
      EXPECT_FALSE(may.count(files)) << stage << " may include " << files;
  }
}

// The checker itself: a stage that includes io/ is caught.
TEST(Layers, AStageIncludingIoIsCaught) {
  const fs::path root = fs::temp_directory_path() / "semsegmap_test_layers";
  fs::remove_all(root);
  fs::create_directories(root / "segment");
  std::ofstream(root / "segment" / "bad.cpp") << "#include \"semsegmap/io/dataset_format.h\"\n";
  std::ofstream(root / "segment" / "good.cpp") << "#include \"semsegmap/core/pose.h\"\n"
                                               << "// #include \"semsegmap/io/x.h\" in a comment\n";
  const auto found = violations(root);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_NE(found[0].file.find("bad.cpp"), std::string::npos);
  fs::remove_all(root);
}

// One CMake library per folder, named after it.
TEST(Layers, EveryFolderIsOneLibrary) {
  std::ifstream cmake(kLibrary / "CMakeLists.txt");
  const std::string text((std::istreambuf_iterator<char>(cmake)), {});
  for (const auto& entry : fs::directory_iterator(kLibrary)) {
    if (!entry.is_directory()) continue;
    const std::string folder = entry.path().filename().string();
    EXPECT_NE(text.find("semsegmap_library(" + folder + ")"), std::string::npos) << folder;
    EXPECT_TRUE(allowed().count(folder)) << folder;
  }
}
