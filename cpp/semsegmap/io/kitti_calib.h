// KITTI's calibration text files ("key: v1 v2 ..." per line) and the sensor models built from
// them; shared by the KITTI raw and SemanticKITTI readers.
#pragma once

#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/frame.h"
#include "semsegmap/core/pose.h"
#include "semsegmap/core/sensor_rig.h"

namespace semsegmap {

// One calibration file, read whole. Values stay text until asked for, because some keys
// (calib_time) are not numbers. Every error is a std::runtime_error "<file>: <key>: <problem>".
class KittiCalibFile {
 public:
  // Throws when the file is missing, a line has no "key:", or a key appears twice.
  explicit KittiCalibFile(const std::filesystem::path& path);

  const std::filesystem::path& path() const { return path_; }
  bool has(const std::string& key) const { return entries_.count(key) != 0; }

  // Exactly `count` finite numbers, in file order.
  std::vector<double> numbers(const std::string& key, size_t count) const;
  // A rows x cols matrix stored row-major on one line (P_rect_02: 3 x 4).
  Eigen::MatrixXd matrix(const std::string& key, int rows, int cols) const;
  // A 3 x 3 matrix that must be a proper rotation up to the file's 7 printed digits; returned
  // as written (not re-orthonormalised) so that projections match the KITTI devkit exactly.
  Eigen::Matrix3d rotation(const std::string& key) const;
  // Rotation key + 3-vector translation key (calib_velo_to_cam.txt's R and T).
  Pose transform(const std::string& rotation_key, const std::string& translation_key) const;
  // A 3 x 4 [R | t] on one key (SemanticKITTI's calib.txt Tr).
  Pose transform3x4(const std::string& key) const;

 private:
  std::runtime_error error(const std::string& key, const std::string& problem) const;
  const std::string& text(const std::string& key) const;

  std::filesystem::path path_;
  std::map<std::string, std::string> entries_;
};

// Splits at whitespace and parses every token as a finite number; throws
// std::invalid_argument "'<token>' is not a finite number" so callers can add file and key.
std::vector<double> parseNumbers(std::string_view text);

// Throws std::runtime_error "<where>: not a rotation matrix (...)" unless R is orthonormal with
// determinant +1 within 1e-3 (the tolerance SensorRig::validate uses).
void checkRotation(const Eigen::Matrix3d& R, const std::string& where);

// The rotation closest to M (SVD), for poses read from files printed with few digits, so that
// Pose::inverse(), which assumes orthonormality, stays exact.
Eigen::Matrix3d nearestRotation(const Eigen::Matrix3d& M);

// The files `dir`/*`extension` (e.g. ".bin"), which KITTI names by their zero-padded frame
// number, sorted by that number. Throws naming the folder when it is missing and naming a file
// whose name is not a number.
std::vector<std::pair<size_t, std::filesystem::path>> listKittiFrames(
    const std::filesystem::path& dir, const std::string& extension);

// The time of scan `number`: its line of `times` when the dataset has a times file (read from
// `times_path`; throws naming it when it has no line for the scan), else number / rate_hz.
double kittiScanTime(const std::vector<double>* times, const std::filesystem::path& times_path,
                     size_t number, double rate_hz);

// A frame of scan `path` (KITTI's .bin, read with readLidarBin) and nothing else yet.
Frame kittiScanFrame(size_t index, double timestamp_s, const std::filesystem::path& path);
// std::out_of_range "<dataset>: frame <index> out of range (<frames> frames)".
// One line of `per_line` numbers per entry (times.txt, poses.txt); blank lines are skipped but
// counted, so that the line numbers in errors are the file's.
std::vector<std::vector<double>> readNumberLines(const std::filesystem::path& path,
                                                 size_t per_line);

// A KITTI pose file: per line the 12 numbers of a row-major 3x4 [R | t], each R a rotation
// up to the printed digits. Throws std::runtime_error "<file>:<line>: ..." otherwise.
std::vector<Pose> readKittiPoses(const std::filesystem::path& path);

// KITTI odometry's poses are of camera 0; calib.txt's Tr (Velodyne -> camera 0) turns them into
// LiDAR poses in the first LiDAR frame: T_world_lidar = Tr^-1 * T_world_cam0 * Tr.
std::vector<Pose> kittiLidarPoses(const std::vector<Pose>& camera0_poses, const Pose& Tr);

// The camera of KITTI projection matrix `p_key` (3 x 4, "P2" of an odometry calib.txt) as our
// pinhole camera of width x height, such that camera.project(camera.T_camera_lidar * X) equals
// P * X for every point X in the reference camera's frame: P = K [I | K^-1 p] is split into the
// intrinsics K and T_camera_lidar = Translation(K^-1 p). Callers compose T_camera_lidar with the
// reference camera's extrinsic. Throws naming the file and key when P has skew, a third row
// other than [0 0 1 *] or a non-positive focal length.
Camera kittiProjectionCamera(const KittiCalibFile& calib, const std::string& p_key, int width,
                             int height);

// KITTI raw's rectified camera `index` (2 = left color) as our Camera, such that
// camera.project(camera.T_camera_lidar * X) equals the devkit's
// P_rect_0i * R_rect_00 * [R|T]_velo_to_cam * X for every LiDAR point X. P_rect_0i = K [I | K^-1 p]
// is split into the intrinsics K and a translation K^-1 p (the stereo baseline), so
// T_camera_lidar = Translation(K^-1 p) * R_rect_00 * T_cam0_velo. Size from S_rect_0i.
Camera kittiRectifiedCamera(const KittiCalibFile& cam_to_cam, const KittiCalibFile& velo_to_cam,
                            int index);

}  // namespace semsegmap
