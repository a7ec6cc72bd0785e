// Reading back the CSV files the commands write (localizations.csv, matches.csv, loops.csv,
// segments.csv): a header line, then plain comma-separated fields without quoting, read by
// column name so that a column added later does not break an older reader.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace semsegmap {

// One line's comma-separated fields (no quoting; a trailing '\r' of a Windows editor dropped).
std::vector<std::string> splitCsvFields(const std::string& line);

class CsvTable {
 public:
  // Throws std::runtime_error "<path>: cannot open", "<path>: empty (no header line)" or
  // "<path>:<line>: N fields where the header has M".
  static CsvTable read(const std::filesystem::path& path);

  size_t rows() const { return rows_.size(); }
  const std::filesystem::path& path() const { return path_; }
  bool has(const std::string& column) const;
  // Throws "<path>: no column 'name' (its header: ...)".
  size_t column(const std::string& name) const;

  const std::string& text(size_t row, size_t column) const { return rows_.at(row).at(column); }
  // Throws "<path>:<line>: column 'name': 'text' is not a number" (also for an empty field).
  double number(size_t row, size_t column) const;
  // An empty field is nothing (e.g. errors without ground truth); anything else as number().
  std::optional<double> optionalNumber(size_t row, size_t column) const;
  // A number that must be a whole number >= 0 (a frame index, a count).
  size_t count(size_t row, size_t column) const;

 private:
  [[noreturn]] void fail(size_t row, size_t column, const std::string& what) const;

  std::filesystem::path path_;
  std::vector<std::string> header_;
  std::vector<std::vector<std::string>> rows_;
  std::vector<size_t> lines_;  // the file's line number of each row, for the errors
};

}  // namespace semsegmap
