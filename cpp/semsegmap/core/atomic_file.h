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

// Called with every file the writes above put in place where none was before, from any thread
// (one at a time): outputs/run_output.h's RunOutputs records them, to remove the files of a command
// that fails. An empty function (the default) turns it off.
void setNewFileObserver(std::function<void(const std::filesystem::path&)> observer);

// Whole file as bytes; throws std::runtime_error "<path>: cannot open" when missing/unreadable.
std::string readFileBytes(const std::filesystem::path& path);

}  // namespace semsegmap
