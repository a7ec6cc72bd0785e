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

// While alive, calls observer(path) with every file the writes above put in place where none was
// before under `scope` (a folder, or one file): outputs/run_output.h's RunOutputs records them, to
// remove the files of a command that fails. From any thread, one call at a time. A file goes only
// to the watches of the innermost scope that holds it, so that watches of different outputs, alive
// at once (two runs in one process), never see each other's files; watches of the same scope all
// see it. Paths are compared absolute and normalised, as given (symbolic links are not resolved).
class NewFileWatch {
 public:
  NewFileWatch(const std::filesystem::path& scope,
               std::function<void(const std::filesystem::path&)> observer);
  ~NewFileWatch();
  NewFileWatch(const NewFileWatch&) = delete;
  NewFileWatch& operator=(const NewFileWatch&) = delete;

 private:
  size_t id_;
};

// Whole file as bytes; throws std::runtime_error "<path>: cannot open" when missing/unreadable.
std::string readFileBytes(const std::filesystem::path& path);

}  // namespace semsegmap
