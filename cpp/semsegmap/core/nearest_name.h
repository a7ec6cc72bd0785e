// The known name a mistyped one was probably meant to be, for "did you mean" hints in errors:
// `semsegmap localise`, `--odometrie`, `rosbg:run.bag`.
#pragma once

#include <string>
#include <vector>

namespace semsegmap {

// Edits (insertions, deletions, substitutions, swaps of two neighbours) that turn `a` into `b`.
size_t editDistance(const std::string& a, const std::string& b);

// The name of `known` nearest `typed` (ignoring case), when it is close enough to be a typo: at
// most 2 edits, or a third of the typed length for long names, and fewer edits than the typed
// name has characters (so that "ab" is not taken for "map"). Empty when none is; the first of
// equally near names wins.
std::string nearestName(const std::string& typed, const std::vector<std::string>& known);

}  // namespace semsegmap
