#include "semsegmap/io/point_cloud_file.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "semsegmap/io/dataset_format.h"

#if SEMSEGMAP_WITH_PCL
#include <pcl/PCLPointCloud2.h>
#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/exceptions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#endif

namespace semsegmap {

namespace fs = std::filesystem;

namespace {

std::string lowerExtension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

#if SEMSEGMAP_WITH_PCL
DecodedPoints decodeCloud(const pcl::PCLPointCloud2& cloud, const fs::path& path) {
  std::vector<PointFieldSpec> fields;
  for (const pcl::PCLPointField& f : cloud.fields)
    fields.push_back({f.name, f.offset, static_cast<FieldType>(f.datatype), f.count});
  const size_t n = static_cast<size_t>(cloud.width) * cloud.height;
  return decodePointFields(fields, cloud.point_step, cloud.data.data(), cloud.data.size(), n,
                           path.string());
}

// More points than any scan has: a header that declares them is corrupt, and PCL would
// allocate them before reading.
constexpr uint64_t kMaxPointsPerScan = uint64_t{1} << 26;

// binary_compressed data starts with its compressed and uncompressed sizes, which PCL allocates
// as read: they must be the header's points and fit in the file.
bool compressedSizesFit(const fs::path& path, uint64_t data_index, uint64_t bytes, uint64_t data) {
  uint32_t sizes[2] = {0, 0};
  std::ifstream in(path, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(data_index));
  if (data < sizeof sizes || !in.read(reinterpret_cast<char*>(sizes), sizeof sizes)) return false;
  return sizes[0] <= data - sizeof sizes && sizes[1] == bytes && sizes[1] <= 512ull * sizes[0];
}

// Counts are saturated at these while a PCD header is read, so that products cannot overflow
// (anything near them is refused anyway).
constexpr uint64_t kCountCap = 1000000000000, kStepCap = uint64_t{1} << 21;

// The header as the PCD format lays it out, read here first: PCL's readHeader allocates the
// points a header declares before anything is checked (a WIDTH of 10^9 is gigabytes).
struct PcdLayout {
  uint64_t points = 0, point_step = 0, values = 0, data_index = 0;
  int data_type = -1;  // 0 ascii, 1 binary, 2 binary_compressed
};

// A header line's words as PCL splits them: at spaces, tabs and carriage returns only.
std::vector<std::string> pcdWords(const std::string& line) {
  std::vector<std::string> words;
  size_t at = 0;
  while ((at = line.find_first_not_of(" \t\r", at)) != std::string::npos) {
    const size_t end = std::min(line.find_first_of(" \t\r", at), line.size());
    words.push_back(line.substr(at, end - at));
    at = end;
  }
  return words;
}

std::vector<uint64_t> countsOf(const std::vector<std::string>& words) {
  std::vector<uint64_t> out;
  for (size_t i = 1; i < words.size(); ++i) {
    const std::string& w = words[i];
    out.push_back(w.size() <= 12 && w.find_first_not_of("0123456789") == std::string::npos
                      ? std::stoull(w)
                      : kCountCap);  // not a count: refused as too large
  }
  return out;
}

// PCL takes a line for a key when its first word starts with it ("COUNT\b" is COUNT), so a word
// that only starts with a key is refused: read by its exact word, the line would go unchecked.
void refuseRunOnKey(const fs::path& path, const std::string& word) {
  for (const char* key : {"VERSION", "FIELDS", "COLUMNS", "SIZE", "TYPE", "COUNT", "WIDTH",
                          "HEIGHT", "VIEWPOINT", "POINTS", "DATA"})
    if (word.rfind(key, 0) == 0 && word != key)
      throw std::runtime_error(path.string() + ": not a readable PCD header: the key '" + key +
                               "' runs on into other characters");
}

void readPcdLine(const fs::path& path, const std::string& line, PcdLayout& l,
                 std::vector<uint64_t>& sizes, std::vector<uint64_t>& counts,
                 uint64_t& width_height) {
  const std::vector<std::string> words = pcdWords(line);
  if (words.empty() || words[0][0] == '#') return;
  const std::string& key = words[0];
  refuseRunOnKey(path, key);
  if (key == "DATA") {
    const std::string type = words.size() > 1 ? words[1] : "";
    l.data_type = type == "ascii" ? 0 : type == "binary" ? 1 : type == "binary_compressed" ? 2 : -1;
    return;
  }
  const std::vector<uint64_t> numbers = countsOf(words);
  const uint64_t first = numbers.empty() ? 0 : std::min(numbers[0], kCountCap);
  if (key == "SIZE") sizes = numbers;
  if (key == "COUNT") counts = numbers;
  if (key == "WIDTH" || key == "HEIGHT") {  // their product, saturated at kCountCap
    const uint64_t other = std::max<uint64_t>(width_height, 1);
    width_height = first != 0 && other > kCountCap / first ? kCountCap : other * first;
  }
  if (key == "POINTS") l.points = first;
}

PcdLayout scanPcdHeader(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  PcdLayout l;
  std::vector<uint64_t> sizes, counts;
  uint64_t width_height = 0;
  std::string line;
  for (int n = 0; n < 100 && l.data_type < 0 && std::getline(in, line); ++n)
    readPcdLine(path, line, l, sizes, counts, width_height);
  if (l.data_type < 0 || sizes.empty())
    throw std::runtime_error(path.string() + ": not a readable PCD header");
  // The format knows fields of 1, 2, 4 and 8 bytes; PCL takes any SIZE at its word and
  // allocates the points with it (SIZE 77777777771 is 12 GB for 3 points).
  for (const uint64_t size : sizes)
    if (size != 1 && size != 2 && size != 4 && size != 8)
      throw std::runtime_error(path.string() +
                               ": not a readable PCD header: a SIZE that is not 1, 2, 4 or 8");
  for (size_t i = 0; i < sizes.size(); ++i) {
    const uint64_t count = i < counts.size() ? std::max<uint64_t>(counts[i], 1) : 1;
    l.point_step = std::min(l.point_step + sizes[i] * std::min(count, kStepCap), kStepCap);
    l.values = std::min(l.values + std::min(count, kStepCap), kStepCap);
  }
  l.points = std::max(l.points, width_height);
  l.data_index = static_cast<uint64_t>(in.tellg());
  return l;
}

// What the header promises must fit in the file before PCL allocates it: binary data byte for
// byte, ASCII at least a byte per value, compressed data at most LZF's best ratio (a few hundred
// to one; a run of zeros compresses about 100:1).
void checkPcdSize(const fs::path& path, const PcdLayout& l) {
  const uint64_t file = fs::file_size(path);
  const uint64_t data = file > l.data_index ? file - l.data_index : 0;
  const uint64_t bytes = l.points * l.point_step;
  const bool fits = l.data_type == 1   ? bytes <= data
                    : l.data_type == 2 ? bytes <= 512 * data
                                       : l.points * l.values <= data;
  if (l.points > kMaxPointsPerScan || l.point_step > (1u << 20) || !fits)
    throw std::runtime_error(path.string() + ": truncated or corrupt: the header promises " +
                             std::to_string(l.points) + " points of " +
                             std::to_string(l.point_step) + " bytes, the file holds " +
                             std::to_string(file) + " bytes");
  if (l.data_type == 2 && !compressedSizesFit(path, l.data_index, bytes, data))
    throw std::runtime_error(path.string() +
                             ": corrupt binary_compressed data: its sizes are not those of the "
                             "header's " +
                             std::to_string(l.points) + " points");
}

// PCL prints its own diagnostics; ours replace them while it reads.
struct QuietPcl {
  pcl::console::VERBOSITY_LEVEL level = pcl::console::getVerbosityLevel();
  QuietPcl() { pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS); }
  ~QuietPcl() { pcl::console::setVerbosityLevel(level); }
};

// PCL takes a field's place (offset, point_step) from SIZE and COUNT but writes values of the
// width its TYPE implies, with TYPE defaulting to 4-byte floats and later lines overriding
// earlier ones: "SIZE 1 1 1" without a TYPE, or a second SIZE after the TYPE, makes it write
// past the end of its buffer (heap overflows, behind a fuzzer finding). Every field must hold
// what PCL will write into it, its buffer hold every point, and the point be the size the file
// was checked against.
void checkPcdFields(const fs::path& path, const pcl::PCLPointCloud2& header,
                    const PcdLayout& layout) {
  for (const pcl::PCLPointField& f : header.fields) {
    const uint64_t size = pcl::getFieldSize(f.datatype);
    if (size == 0 || f.offset + size * std::max<uint64_t>(f.count, 1) > header.point_step)
      throw std::runtime_error(path.string() + ": not a readable PCD header: the field '" + f.name +
                               "' has a TYPE that does not fit its SIZE and COUNT");
  }
  // PCL sizes its buffer when it reads POINTS, with the point size known by then: POINTS before
  // SIZE or COUNT leaves it too small for what they declare next (another overflow).
  const uint64_t points = static_cast<uint64_t>(header.width) * header.height;
  if (header.data.size() != points * header.point_step)
    throw std::runtime_error(path.string() +
                             ": not a readable PCD header: POINTS comes before SIZE or COUNT");
  if (header.point_step != layout.point_step)
    throw std::runtime_error(path.string() + ": not a readable PCD header: PCL reads points of " +
                             std::to_string(header.point_step) + " bytes where SIZE and COUNT " +
                             "give " + std::to_string(layout.point_step) +
                             " (a key given twice or out of order, or a COUNT of 0)");
}

// PCL returns a code (or throws, naming no file); the header is read first so that the error
// says what is wrong (a truncated binary file, a point count the data does not hold).
DecodedPoints readPcd(const fs::path& path) {
  const PcdLayout layout = scanPcdHeader(path);
  checkPcdSize(path, layout);
  const QuietPcl quiet;
  pcl::PCDReader reader;
  pcl::PCLPointCloud2 header, cloud;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0, data_type = 0, rc = -1;
  unsigned int data_index = 0;
  try {
    rc = reader.readHeader(path.string(), header, origin, orientation, version, data_type,
                           data_index);
  } catch (const std::exception&) {  // PCLException, and std::out_of_range of its vectors
    rc = -1;
  }
  // PCL accepts a header without fields or data (an empty file) and then crashes reading it.
  if (rc < 0 || header.fields.empty() || data_index == 0 || data_index > fs::file_size(path))
    throw std::runtime_error(path.string() + ": not a readable PCD header");
  checkPcdFields(path, header, layout);
  try {
    rc = reader.read(path.string(), cloud);
  } catch (const std::exception&) {  // PCLException, and std::out_of_range of its vectors
    rc = -1;
  }
  const uint64_t points = static_cast<uint64_t>(header.width) * header.height;
  if (rc < 0 || static_cast<uint64_t>(cloud.width) * cloud.height != points)
    throw std::runtime_error(path.string() + ": the data does not hold the " +
                             std::to_string(points) + " points its header declares");
  return decodeCloud(cloud, path);
}

// PCL's PLY parser asserts (aborts) on headers it does not expect and allocates the vertex
// count it reads, so the header is checked first against the grammar of the PLY format: known
// keywords and types only, a vertex element with scalar x, y and z, and counts that fit in the
// file (at least a byte a property, ASCII or binary).
bool isPlyType(const std::string& type) {
  static const std::set<std::string> types = {
      "char", "uchar", "short", "ushort", "int",   "uint",   "float",   "double",
      "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
  return types.count(type) != 0;
}

struct PlyHeader {
  uint64_t vertices = 0, properties = 0;  // of the vertex element
  std::set<std::string> vertex_fields;
  std::vector<std::string> vertex_order;  // the vertex element's scalar properties, in order
  bool ended = false;
};

void readPlyLine(const std::string& line, PlyHeader& h, bool& in_vertex, uint64_t& elements) {
  std::istringstream words(line);
  std::string word, a, b, c, name, rest;
  words >> word;
  if (word == "comment" || word == "obj_info") return;
  if (word == "end_header" && !(words >> rest)) {
    h.ended = true;
  } else if (word == "element" && words >> a >> c && !(words >> rest) &&
             c.find_first_not_of("0123456789") == std::string::npos && c.size() < 12) {
    in_vertex = a == "vertex";
    if (in_vertex) h.vertices = std::stoull(c);
    elements += std::stoull(c);
  } else if (word == "property" && words >> a >> b && isPlyType(a) && !(words >> rest)) {
    if (in_vertex && !h.vertex_fields.insert(b).second) throw std::invalid_argument("twice");
    const bool colour = b == "red" || b == "green" || b == "blue" || b == "alpha";
    if (in_vertex && colour && a != "uchar" && a != "uint8")  // PCL asserts on any other
      throw std::invalid_argument("a colour that is not uchar");
    if (in_vertex) h.vertex_order.push_back(b);
    h.properties += in_vertex;
  } else if (word == "property" && a == "list" && words >> c >> name && isPlyType(b) &&
             isPlyType(c) && !(words >> rest)) {
    // PCL asserts on the contents of some vertex lists; a point cloud's vertices have none.
    if (in_vertex) throw std::invalid_argument("a list property in the vertex element");
  } else {
    throw std::invalid_argument(line.substr(0, 40));
  }
}

// PCL packs red, green, blue (and alpha) into one rgb field and asserts when they do not come
// together in that order: a vertex has all three, consecutively, or none.
bool coloursPclReads(const std::vector<std::string>& order) {
  const auto at = [&](const char* name) {
    return std::find(order.begin(), order.end(), name) - order.begin();
  };
  const auto n = static_cast<std::ptrdiff_t>(order.size());
  const std::ptrdiff_t red = at("red"), green = at("green"), blue = at("blue"), alpha = at("alpha");
  if (red == n && green == n && blue == n && alpha == n) return true;
  return red < n && green == red + 1 && blue == red + 2 && (alpha == n || alpha == red + 3);
}

void checkPlyHeader(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  PlyHeader h;
  bool in_vertex = false;
  uint64_t elements = 0;
  const auto refuse = [&](const std::string& what) {
    throw std::runtime_error(path.string() + ": not a PLY file this reader takes (" + what + ")");
  };
  const auto next = [&] {  // a line without the '\r' of a file written on Windows
    const bool ok = static_cast<bool>(std::getline(in, line));
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return ok;
  };
  next();
  if (line != "ply") refuse("no 'ply' line");
  next();
  if (line != "format ascii 1.0" && line != "format binary_little_endian 1.0" &&
      line != "format binary_big_endian 1.0")
    refuse("no 'format ascii|binary_little_endian|binary_big_endian 1.0' line");
  for (int n = 0; n < 1000 && !h.ended && next(); ++n) {
    try {
      readPlyLine(line, h, in_vertex, elements);
    } catch (const std::invalid_argument&) {
      refuse("a header line of PLY's grammar expected");
    }
  }
  if (!h.ended) refuse("no end_header");
  for (const char* axis : {"x", "y", "z"})
    if (!h.vertex_fields.count(axis)) refuse("the vertex element has no scalar x, y and z");
  if (!coloursPclReads(h.vertex_order)) refuse("red, green and blue must follow each other");
  if (h.vertices > kMaxPointsPerScan || elements > kMaxPointsPerScan ||
      h.vertices * h.properties > static_cast<uint64_t>(fs::file_size(path)))
    throw std::runtime_error(path.string() + ": truncated or corrupt: the header promises " +
                             std::to_string(h.vertices) + " vertices of " +
                             std::to_string(h.properties) + " properties, the file holds " +
                             std::to_string(fs::file_size(path)) + " bytes");
}

DecodedPoints readPly(const fs::path& path) {
  checkPlyHeader(path);
  const QuietPcl quiet;
  pcl::PLYReader reader;
  pcl::PCLPointCloud2 cloud;
  int rc = -1;
  try {
    rc = reader.read(path.string(), cloud);
  } catch (const std::exception&) {  // PCLException, and std::out_of_range of its vectors
    rc = -1;
  }
  if (rc < 0) throw std::runtime_error(path.string() + ": not a readable PLY file");
  return decodeCloud(cloud, path);
}
#else
DecodedPoints needsPcl(const fs::path& path) {
  throw std::runtime_error(path.string() +
                           ": PCD and PLY files are read with PCL, which this build left out "
                           "(reconfigure with -DSEMSEGMAP_WITH_PCL=ON)");
}
DecodedPoints readPcd(const fs::path& path) {
  return needsPcl(path);
}
DecodedPoints readPly(const fs::path& path) {
  return needsPcl(path);
}
#endif

}  // namespace

bool isPointCloudFile(const fs::path& path) {
  const std::string ext = lowerExtension(path);
  return ext == ".pcd" || ext == ".ply" || ext == ".bin";
}

DecodedPoints readPointCloudFile(const fs::path& path) {
  if (!fs::is_regular_file(path)) throw std::runtime_error(path.string() + ": no such file");
  const std::string ext = lowerExtension(path);
  if (ext == ".pcd") return readPcd(path);
  if (ext == ".ply") return readPly(path);
  if (ext == ".bin") {
    DecodedPoints d;
    d.points = readLidarBin(path);
    d.intensity_field = "intensity";
    return d;
  }
  throw std::runtime_error(path.string() + ": not a point cloud file (.pcd, .ply or .bin)");
}

}  // namespace semsegmap
