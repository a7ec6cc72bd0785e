// Files are written to a temporary name beside the target and renamed, so a crash or a full
// disk never leaves half a file under the real name.
#pragma once

#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

namespace semsegmap {

// Calls write(stream) on a temporary file, flushes, checks the stream and renames it over
// `path`. Throws std::runtime_error naming `path` when anything fails; the temporary is removed.
void writeFileAtomically(const std::filesystem::path& path,
                         const std::function<void(std::ostream&)>& write);
void writeBytesAtomically(const std::filesystem::path& path, const std::string& bytes);

// Whole file as bytes; throws std::runtime_error "<path>: cannot open" when missing/unreadable.
std::string readFileBytes(const std::filesystem::path& path);

}  // namespace semsegmap
