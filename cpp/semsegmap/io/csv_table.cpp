#include "semsegmap/io/csv_table.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

namespace semsegmap {

std::vector<std::string> splitCsvFields(const std::string& line) {
  std::vector<std::string> fields(1);
  for (const char c : line) {
    if (c == ',')
      fields.emplace_back();
    else if (c != '\r')  // a file that went through a Windows editor
      fields.back() += c;
  }
  return fields;
}

namespace {

std::string joined(const std::vector<std::string>& fields) {
  std::string s;
  for (const std::string& f : fields) s += (s.empty() ? "" : ",") + f;
  return s;
}

}  // namespace

CsvTable CsvTable::read(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  CsvTable t;
  t.path_ = path;
  std::string line;
  size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line == "\r") continue;
    std::vector<std::string> fields = splitCsvFields(line);
    if (t.header_.empty()) {
      t.header_ = std::move(fields);
      continue;
    }
    if (fields.size() != t.header_.size())
      throw std::runtime_error(path.string() + ":" + std::to_string(number) + ": " +
                               std::to_string(fields.size()) + " fields where the header has " +
                               std::to_string(t.header_.size()));
    t.rows_.push_back(std::move(fields));
    t.lines_.push_back(number);
  }
  if (t.header_.empty()) throw std::runtime_error(path.string() + ": empty (no header line)");
  return t;
}

bool CsvTable::has(const std::string& column) const {
  for (const std::string& h : header_)
    if (h == column) return true;
  return false;
}

size_t CsvTable::column(const std::string& name) const {
  for (size_t i = 0; i < header_.size(); ++i)
    if (header_[i] == name) return i;
  throw std::runtime_error(path_.string() + ": no column '" + name +
                           "' (its header: " + joined(header_) + ")");
}

void CsvTable::fail(size_t row, size_t column, const std::string& what) const {
  throw std::runtime_error(path_.string() + ":" + std::to_string(lines_.at(row)) + ": column '" +
                           header_.at(column) + "': " + what);
}

double CsvTable::number(size_t row, size_t column) const {
  const std::string& s = text(row, column);
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v))
    fail(row, column, "'" + s + "' is not a number");
  return v;
}

std::optional<double> CsvTable::optionalNumber(size_t row, size_t column) const {
  if (text(row, column).empty()) return std::nullopt;
  return number(row, column);
}

size_t CsvTable::count(size_t row, size_t column) const {
  const double v = number(row, column);
  if (v < 0 || v != std::floor(v) || v > 1e15)
    fail(row, column, "'" + text(row, column) + "' is not a whole number >= 0");
  return static_cast<size_t>(v);
}

}  // namespace semsegmap
