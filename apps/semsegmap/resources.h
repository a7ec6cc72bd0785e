// Where the configs and models that the commands' defaults name are: beside an installed binary
// (<prefix>/share/semsegmap, as `cmake --install` lays it out), or else in the source tree the
// binary was built from. Never the current directory, so every command works from anywhere; a
// path the user types is the user's own, relative to where they are.
#pragma once

#include <filesystem>
#include <string>

namespace semsegmap::app {

// The folder holding config/ and models/. Throws std::runtime_error naming where it looked.
std::filesystem::path dataDir();

// `relative` (e.g. "config/semsegmap.yaml") inside dataDir().
std::filesystem::path shippedFile(const std::string& relative);

}  // namespace semsegmap::app
