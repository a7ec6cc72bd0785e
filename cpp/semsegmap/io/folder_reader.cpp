#include "semsegmap/io/folder_reader.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "semsegmap/core/diagnostics.h"
#include "semsegmap/core/shown_text.h"
#include "semsegmap/core/time_association.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/io/kitti_calib.h"
#include "semsegmap/io/point_cloud_file.h"

namespace semsegmap {

namespace fs = std::filesystem;

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// The regular files of `folder` that `keep` accepts, sorted by name.
std::vector<fs::path> listFiles(const fs::path& folder, bool (*keep)(const fs::path&)) {
  if (!fs::is_directory(folder)) throw std::runtime_error(folder.string() + ": no such folder");
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.is_regular_file() && keep(entry.path())) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<double> readTimesFile(const fs::path& path, size_t expected) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open the times file");
  std::vector<double> times;
  std::string line;
  for (size_t number = 1; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream ss(line);
    double t = 0;
    if (!(ss >> t) || !std::isfinite(t))
      throw std::runtime_error(path.string() + ":" + std::to_string(number) +
                               ": expected a time in seconds");
    times.push_back(t);
  }
  if (times.size() != expected)
    throw std::runtime_error(path.string() + ": " + std::to_string(times.size()) + " times for " +
                             std::to_string(expected) + " scans");
  return times;
}

// Frame numbers of files from their names, the files put in number order (0, 38, 120 as well as
// 000000, 000038, 000120); empty unless every name is a frame number.
std::vector<size_t> sortByFrameNumber(std::vector<fs::path>& files) {
  std::vector<std::pair<size_t, fs::path>> numbered;
  for (const fs::path& f : files) {
    const auto n = frameNumberFromFileName(f.stem().string());
    if (!n) return {};
    numbered.emplace_back(*n, f);
  }
  std::sort(numbered.begin(), numbered.end());
  std::vector<size_t> numbers;
  for (size_t i = 0; i < numbered.size(); ++i) {
    if (i > 0 && numbered[i].first == numbered[i - 1].first)
      throw std::runtime_error(numbered[i].second.string() + ": a second scan of frame " +
                               std::to_string(numbered[i].first) + " (" +
                               numbered[i - 1].second.filename().string() + ")");
    files[i] = numbered[i].second;
    numbers.push_back(numbered[i].first);
  }
  return numbers;
}

// Times of files from their names; nothing unless every name is a time.
std::optional<std::vector<double>> timesFromNames(const std::vector<fs::path>& files) {
  std::vector<double> times;
  for (const fs::path& f : files) {
    const auto t = timeFromFileName(f.stem().string());
    if (!t) return std::nullopt;
    times.push_back(*t);
  }
  return times;
}

double parsePositive(const std::string& spec, const std::string& key, const std::string& value) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != value.size() || !(v > 0) || !std::isfinite(v))
    throw std::invalid_argument("dataset '" + spec + "': " + key +
                                " expects a positive number, got '" + value + "'");
  return v;
}

}  // namespace

fs::path parseFolderSpec(const std::string& spec, const std::string& args, FolderOptions& options) {
  std::stringstream ss(args);
  std::string item;
  std::getline(ss, item, ',');
  const fs::path dir = item;
  if (dir.empty()) throw std::invalid_argument("dataset '" + spec + "': no folder after folder:");
  while (std::getline(ss, item, ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos)
      throw std::invalid_argument("dataset '" + spec + "': expected key=value, got '" + item + "'");
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "rig")
      options.rig = value;
    else if (key == "times")
      options.times = value;
    else if (key == "tolerance")
      options.tolerance_s = parsePositive(spec, key, value);
    else
      throw std::invalid_argument("dataset '" + spec + "': unknown key '" + key +
                                  "' (expected rig, times or tolerance)");
  }
  return dir;
}

bool isPictureFile(const fs::path& p) {
  const std::string ext = lower(p.extension().string());
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg";
}

std::optional<double> timeFromFileName(const std::string& stem) {
  if (stem.empty() || !std::isdigit(static_cast<unsigned char>(stem[0]))) return std::nullopt;
  const size_t dot = stem.find('.');
  const std::string whole = stem.substr(0, dot);
  const bool digits_only =
      std::all_of(whole.begin(), whole.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
  if (!digits_only) return std::nullopt;
  if (dot != std::string::npos) {
    const std::string frac = stem.substr(dot + 1);
    if (frac.empty() || !std::all_of(frac.begin(), frac.end(),
                                     [](unsigned char c) { return std::isdigit(c) != 0; }))
      return std::nullopt;
    return std::stod(stem);  // seconds with a fraction
  }
  const size_t n = whole.size();
  if (n >= 18) return std::stod(whole.substr(0, n - 9)) + std::stod(whole.substr(n - 9)) * 1e-9;
  if (n >= 15) return std::stod(whole) * 1e-6;
  if (n >= 12) return std::stod(whole) * 1e-3;
  const double v = std::stod(whole);
  if (v >= 1e8) return v;
  return std::nullopt;  // a frame number
}

std::optional<size_t> frameNumberFromFileName(const std::string& stem) {
  const bool digits_only = !stem.empty() && std::all_of(stem.begin(), stem.end(), [](char c) {
    return std::isdigit(static_cast<unsigned char>(c)) != 0;
  });
  if (!digits_only || timeFromFileName(stem)) return std::nullopt;
  return static_cast<size_t>(std::stoull(stem));
}

std::optional<size_t> FolderReader::frameNumber(size_t index) {
  if (numbers_.empty()) return std::nullopt;
  return numbers_.at(index);
}

RigFile readFolderRig(const fs::path& dir, const FolderOptions& options, fs::path& rig_path) {
  if (!fs::is_directory(dir)) throw std::runtime_error(dir.string() + ": no such folder");
  rig_path = !options.rig.empty() ? options.rig
                                  : (fs::exists(dir / "rig.yaml") ? dir / "rig.yaml" : fs::path());
  RigFile rig;
  if (!rig_path.empty()) return readRigFile(rig_path);
  rig.rig.lidar.hfov_deg = 360.0;
  rig.rig.rate_hz = 10.0;  // as a rig file without rate_hz
  note(dir.string() + " has no rig file (rig.yaml, or " + optionText("rig", "FILE") +
       "): LiDAR only at " + shownNumber(rig.rig.rate_hz) + " Hz, the base frame is the LiDAR");
  return rig;
}

std::string folderName(const fs::path& dir, const RigFile& rig) {
  return !rig.name.empty() ? rig.name : "folder:" + fs::absolute(dir).filename().string();
}

FolderReader::FolderReader(const fs::path& dir, const FolderOptions& options) : dir_(dir) {
  fs::path rig_path;
  const RigFile rig = readFolderRig(dir_, options, rig_path);
  info_.name = folderName(dir_, rig);
  info_.rig = rig.rig;
  info_.classes = ClassTable::Default();

  const fs::path lidar_dir = rig.lidar_folder.empty() ? dir_ : dir_ / rig.lidar_folder;
  scans_ = listFiles(lidar_dir, &isPointCloudFile);
  if (scans_.empty())
    throw std::runtime_error(lidar_dir.string() + ": no scans (.pcd, .ply or .bin files)");
  numbers_ = sortByFrameNumber(scans_);
  const fs::path times_path =
      !options.times.empty() ? options.times
                             : (fs::exists(dir_ / "times.txt") ? dir_ / "times.txt" : fs::path());
  if (!times_path.empty()) {
    times_ = readTimesFile(times_path, scans_.size());
  } else if (auto from_names = timesFromNames(scans_)) {
    times_ = std::move(*from_names);
  } else {
    madeUpTimes(lidar_dir);
  }
  if (!std::is_sorted(times_.begin(), times_.end()))
    throw std::runtime_error(lidar_dir.string() + ": the scan times do not increase in name order");
  tolerance_s_ = options.tolerance_s > 0 ? options.tolerance_s : 0.5 / info_.rig.rate_hz;
  pictures_.resize(info_.rig.cameras.size());
  for (size_t c = 0; c < info_.rig.cameras.size(); ++c)
    pairPictures(c, dir_ / rig.camera_folders[c]);
  describeOrigin(rig_path, lidar_dir, times_path);
}

// What `semsegmap info` shows: the rig file, the scans' pattern and where their times come from.
void FolderReader::describeOrigin(const fs::path& rig, const fs::path& lidar_dir,
                                  const fs::path& times) {
  DatasetOrigin& o = info_.origin;
  o.kind = rig.empty() ? "folder, no rig file (a LiDAR alone)" : "folder, rig " + rig.string();
  std::vector<std::string> extensions;
  for (const fs::path& scan : scans_)
    if (std::find(extensions.begin(), extensions.end(), scan.extension().string()) ==
        extensions.end())
      extensions.push_back(scan.extension().string());
  o.lidar = (lidar_dir / "*").string();
  for (size_t k = 0; k < extensions.size(); ++k) o.lidar += (k == 0 ? "" : "|") + extensions[k];
  o.lidar += !times.empty()          ? ", times from " + times.string()
             : info_.has_frame_times ? ", times from the names"
                                     : ", no times (made up from the rate)";
  for (size_t c = 0; c < info_.rig.cameras.size(); ++c) {
    const fs::path& first = *std::find_if(pictures_[c].begin(), pictures_[c].end(),
                                          [](const fs::path& p) { return !p.empty(); });
    o.cameras.push_back((first.parent_path() / "*").string() + first.extension().string());
  }
}

// Scans without times in their names or a times file: scan N at N periods when the names are
// frame numbers (sparse frames keep their spacing), else one period apart in name order. Such
// times pair pictures, but no pose file is matched to them (DatasetInfo::has_frame_times).
void FolderReader::madeUpTimes(const fs::path& lidar_dir) {
  info_.has_frame_times = false;
  for (size_t i = 0; i < scans_.size(); ++i)
    times_.push_back(static_cast<double>(numbers_.empty() ? i : numbers_[i]) / info_.rig.rate_hz);
  if (scans_.size() < 2) return;
  note(lidar_dir.string() + ": the scans' names are no times and there is no times file: " +
       (numbers_.empty()
            ? "scans are taken " + shownNumber(1.0 / info_.rig.rate_hz) + " s apart in name order"
            : "scan N is taken at N x " + shownNumber(1.0 / info_.rig.rate_hz) + " s"));
}

namespace {

void checkPictureSize(const Image& picture, const Camera& camera, const fs::path& path) {
  if (picture.width != camera.width || picture.height != camera.height)
    throw std::runtime_error(path.string() + ": the picture is " + std::to_string(picture.width) +
                             "x" + std::to_string(picture.height) + " but camera '" + camera.name +
                             "' of the rig is " + std::to_string(camera.width) + "x" +
                             std::to_string(camera.height));
}

}  // namespace

void FolderReader::pairPictures(size_t camera, const fs::path& folder) {
  const Camera& cam = info_.rig.cameras[camera];
  const std::vector<fs::path> pictures = listFiles(folder, &isPictureFile);
  if (pictures.empty())
    throw std::runtime_error(folder.string() + ": no pictures (.png, .jpg) of camera '" + cam.name +
                             "'");
  std::vector<fs::path>& paired = pictures_[camera];
  paired.assign(scans_.size(), fs::path());
  std::map<std::string, fs::path> by_stem;
  for (const fs::path& p : pictures) by_stem[p.stem().string()] = p;
  size_t same_name = 0;
  for (size_t i = 0; i < scans_.size(); ++i) {
    const auto it = by_stem.find(scans_[i].stem().string());
    if (it != by_stem.end()) paired[i] = it->second, ++same_name;
  }
  if (same_name == 0) {  // not named as the scans: by time
    const auto picture_times = timesFromNames(pictures);
    if (!picture_times)
      throw std::runtime_error(folder.string() + ": cannot pair the pictures of camera '" +
                               cam.name +
                               "' with the scans: name them as the scans, or by "
                               "their times (e.g. 1650000000.123456.png)");
    const Association a = associateNearest(times_, *picture_times, tolerance_s_);
    for (size_t i = 0; i < scans_.size(); ++i)
      if (a.match[i]) paired[i] = pictures[*a.match[i]];
  }
  const size_t unpaired = static_cast<size_t>(std::count(paired.begin(), paired.end(), fs::path()));
  if (unpaired > 0)
    note("camera '" + cam.name + "': " + std::to_string(unpaired) + " of " +
         std::to_string(scans_.size()) + " scans have no picture within " +
         shownNumber(tolerance_s_) + " s; their points get no colour from it");
  if (unpaired == scans_.size())
    throw std::runtime_error(folder.string() + ": no picture of camera '" + cam.name +
                             "' lies within " + std::to_string(tolerance_s_) + " s of a scan");
  // One picture read up front: a size that disagrees with the rig fails before the work.
  const fs::path& first =
      *std::find_if(paired.begin(), paired.end(), [](const fs::path& p) { return !p.empty(); });
  checkPictureSize(readColorImage(first), cam, first);
}

Frame FolderReader::frame(size_t index) {
  if (index >= scans_.size()) throwFrameOutOfRange(info_.name, index, scans_.size());
  Frame f;
  f.index = index;
  f.number = frameNumber(index);
  f.timestamp_s = times_[index];
  DecodedPoints scan = readPointCloudFile(scans_[index]);
  f.points = std::move(scan.points);
  f.point_times = relativePointTimes(scan.times, f.timestamp_s);
  f.cameras.resize(info_.rig.cameras.size());
  for (size_t c = 0; c < f.cameras.size(); ++c) {
    const fs::path& picture = pictures_[c][index];
    if (picture.empty()) continue;
    f.cameras[c].rgb = readColorImage(picture);
    checkPictureSize(f.cameras[c].rgb, info_.rig.cameras[c], picture);
  }
  return f;
}

}  // namespace semsegmap
