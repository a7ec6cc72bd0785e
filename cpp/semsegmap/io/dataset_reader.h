// Reads a dataset directory in the project's format as a FrameSource.
#pragma once

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "semsegmap/core/frame_source.h"

namespace semsegmap {

class DatasetReader : public FrameSource {
 public:
  // Reads meta.yaml and indexes frames.csv, streamed: memory does not grow with its rows (one
  // file offset per 1024 rows is kept, and each row is parsed again when its frame is read). Every
  // row's frame index and field count are checked at once; the first `frames_to_check` rows (0:
  // all), the frames a run will read, are parsed whole and their files looked up by stat: each
  // present and of a plausible size (scans a multiple of 16 bytes, labels and times 4 bytes a
  // point, pictures at least a PNG's header), so that a missing label image is found before
  // frame 0, not when its frame comes. Throws std::runtime_error naming the file and the problem.
  explicit DatasetReader(const std::filesystem::path& dir, size_t frames_to_check = 0);
  const DatasetInfo& info() const override { return info_; }
  size_t size() const override { return rows_; }
  // Loads the frame's files; a missing, truncated or mis-sized file throws naming that file.
  Frame frame(size_t index) override;
  // From frames.csv: pose files pair scans by time without reading them.
  double frameTime(size_t index) override { return row(index).timestamp_s; }

 private:
  struct Row {
    size_t index;
    double timestamp_s;
    Pose odom;
    std::optional<Pose> gt;
  };
  struct Block {  // where row 1024 k starts
    uint64_t offset;
    size_t line;
  };
  void describeOrigin();  // info_.origin, from meta.yaml and the folders present
  void index(size_t frames_to_check);
  [[noreturn]] void rowError(const std::string& line, size_t line_number, bool have_previous,
                             size_t previous) const;
  // The next line of frames.csv without its '\n' (nor a '\r' before it); false at the end.
  // `bytes` grows by what was consumed.
  bool readLine(std::string& line, uint64_t& bytes, size_t line_number);
  // The line of data row `i` (seeks to its block unless it follows the last one read).
  const std::string& lineOf(size_t i, size_t* line_number);
  Row parse(const std::string& line, size_t line_number) const;
  Row row(size_t i);
  void checkFiles(const Row& row) const;

  std::filesystem::path dir_, csv_;
  DatasetInfo info_;
  size_t rows_ = 0;
  std::vector<Block> blocks_;
  // Camera and time folders present (each then holds a file per frame).
  std::vector<bool> rgb_dirs_, label_dirs_;
  bool times_dir_ = false;
  // The reading position: the next data row and its line number, for sequential reads.
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file_{nullptr, &std::fclose};
  size_t next_row_ = 0, next_line_ = 0;
  std::vector<char> buffer_;  // 1 MB read ahead, [buffer_begin_, buffer_end_) not yet consumed
  size_t buffer_begin_ = 0, buffer_end_ = 0;
  std::string line_;
};

}  // namespace semsegmap
