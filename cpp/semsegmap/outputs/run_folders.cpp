#include "semsegmap/outputs/run_folders.h"

#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "semsegmap/io/csv_table.h"
#include "semsegmap/io/trajectory_file.h"

namespace semsegmap {

namespace {

// `dir`/`name`, which must exist: "<dir>: no <name> (<what it should be>)".
std::filesystem::path needed(const std::filesystem::path& dir, const std::string& name,
                             const std::string& what) {
  if (!std::filesystem::is_directory(dir))
    throw std::runtime_error(dir.string() + ": no such folder (" + what + ")");
  const std::filesystem::path path = dir / name;
  if (!std::filesystem::exists(path))
    throw std::runtime_error(dir.string() + ": no " + name + " (not " + what + ")");
  return path;
}

std::vector<LoopRow> readLoops(const std::filesystem::path& path, size_t poses) {
  const CsvTable t = CsvTable::read(path);
  const size_t frame = t.column("frame"), old_frame = t.column("old_frame"),
               inliers = t.column("inliers"), correction = t.column("correction_m");
  std::vector<LoopRow> loops(t.rows());
  for (size_t i = 0; i < t.rows(); ++i) {
    LoopRow& l = loops[i];
    l.frame = t.count(i, frame);
    l.old_frame = t.count(i, old_frame);
    l.inliers = static_cast<int>(t.count(i, inliers));
    l.correction_m = t.number(i, correction);
    // One pose per frame from frame 0 (pipeline/slam.h): a loop beyond it is another run's.
    if (l.frame >= poses || l.old_frame >= poses)
      throw std::runtime_error(path.string() + ": loop " + std::to_string(i + 1) +
                               " joins frames " + std::to_string(l.old_frame) + " and " +
                               std::to_string(l.frame) + ", beyond the trajectory's " +
                               std::to_string(poses) + " poses");
  }
  return loops;
}

// The header of segments.ply up to "end_header\n", checked line by line; returns the vertices.
size_t readPlyHeader(std::istream& in, const std::filesystem::path& path) {
  const std::vector<std::string> expected = {"ply",
                                             "format binary_little_endian 1.0",
                                             "",
                                             "property float x",
                                             "property float y",
                                             "property float z",
                                             "property uchar red",
                                             "property uchar green",
                                             "property uchar blue",
                                             "property ushort class",
                                             "property int segment",
                                             "end_header"};
  size_t vertices = 0;
  std::string line;
  for (const std::string& want : expected) {
    if (!std::getline(in, line)) throw std::runtime_error(path.string() + ": truncated PLY header");
    if (want.empty()) {  // "element vertex N"
      std::istringstream s(line);
      std::string element, vertex;
      if (!(s >> element >> vertex >> vertices) || element != "element" || vertex != "vertex")
        throw std::runtime_error(path.string() + ": expected 'element vertex N', found '" + line +
                                 "'");
    } else if (line != want) {
      throw std::runtime_error(path.string() + ": not the segments.ply of semsegmap segment ('" +
                               line + "' where '" + want + "' belongs)");
    }
  }
  return vertices;
}

}  // namespace

SlamFolder readSlamFolder(const std::filesystem::path& dir) {
  const std::string what = "the output of semsegmap slam";
  SlamFolder f;
  f.dir = dir;
  // A run over data without frame times writes KITTI files alone (no made-up times): their
  // line i is frame i of the run, which is all the view needs.
  const auto poses = [&dir](const std::string& stem) {
    const std::filesystem::path kitti = dir / (stem + "_kitti.txt");
    if (std::filesystem::exists(dir / (stem + "_tum.txt")) || !std::filesystem::exists(kitti))
      return std::vector<StampedPose>{};
    return readPoseFile(kitti).poses;
  };
  f.trajectory = poses("trajectory");
  if (f.trajectory.empty()) f.trajectory = readTum(needed(dir, "trajectory_tum.txt", what));
  f.odometry = poses("odometry");
  if (f.odometry.empty() && std::filesystem::exists(dir / "odometry_tum.txt"))
    f.odometry = readTum(dir / "odometry_tum.txt");
  if (std::filesystem::exists(dir / "loops.csv"))
    f.loops = readLoops(dir / "loops.csv", f.trajectory.size());
  return f;
}

std::vector<SegmentPoint> readSegmentPointsPly(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  const size_t n = readPlyHeader(in, path);
  constexpr size_t kRecord = 12 + 3 + 2 + 4;
  std::vector<SegmentPoint> points(n);
  char record[kRecord];
  for (size_t i = 0; i < n; ++i) {
    if (!in.read(record, kRecord))
      throw std::runtime_error(path.string() + ": truncated after " + std::to_string(i) + " of " +
                               std::to_string(n) + " points");
    SegmentPoint& p = points[i];
    std::memcpy(p.p.data(), record, 12);
    std::memcpy(p.rgb.data(), record + 12, 3);
    std::memcpy(&p.class_id, record + 15, 2);
    std::memcpy(&p.segment, record + 17, 4);
  }
  if (in.peek() != std::char_traits<char>::eof())
    throw std::runtime_error(path.string() + ": bytes after its " + std::to_string(n) + " points");
  return points;
}

SegmentFolder readSegmentFolder(const std::filesystem::path& dir) {
  const std::string what = "the output of semsegmap segment";
  SegmentFolder f;
  f.dir = dir;
  const CsvTable t = CsvTable::read(needed(dir, "segments.csv", what));
  const size_t id = t.column("id"), points = t.column("points"), x = t.column("centroid_x"),
               y = t.column("centroid_y"), z = t.column("centroid_z"), cls = t.column("class");
  f.segments.resize(t.rows());
  for (size_t i = 0; i < t.rows(); ++i) {
    SegmentRow& s = f.segments[i];
    s.id = static_cast<int64_t>(t.count(i, id));
    s.points = t.count(i, points);
    s.centroid = {static_cast<float>(t.number(i, x)), static_cast<float>(t.number(i, y)),
                  static_cast<float>(t.number(i, z))};
    s.class_name = t.text(i, cls);
  }
  f.points = readSegmentPointsPly(needed(dir, "segments.ply", what));
  return f;
}

}  // namespace semsegmap
