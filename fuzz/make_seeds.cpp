// Writes the seed corpus of every harness from the project's own writers (maps, models, caches,
// datasets, scans, ROS messages) and its own text files (configs, class maps, the example rig),
// so that no binary seed is committed. Usage: make_seeds OUT_DIR SOURCE_DIR
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/artefacts/training_cache.h"
#include "semsegmap/core/binary_io.h"
#include "semsegmap/io/dataset_format.h"
#include "semsegmap/io/dataset_writer.h"
#include "semsegmap/io/label_set.h"
#include "semsegmap/io/ply_writer.h"
#if SEMSEGMAP_WITH_TORCH
#include "semsegmap/describe/learned_net.h"
#endif
#if SEMSEGMAP_WITH_ROS
#include "semsegmap/io/ros_serialization.h"
#endif

namespace fs = std::filesystem;
using namespace semsegmap;

namespace {

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void writeText(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

// The harnesses of checksummed formats append the checksum themselves (fuzz_input.h).
void withoutChecksum(const fs::path& path) {
  const std::string bytes = readText(path);
  writeText(path, bytes.substr(0, bytes.size() - sizeof(uint64_t)));
}

std::vector<LidarPoint> somePoints(int n) {
  std::vector<LidarPoint> points;
  for (int i = 0; i < n; ++i)
    points.push_back({std::cos(0.3f * i) * 5, std::sin(0.3f * i) * 5, 0.1f * i, 0.5f});
  return points;
}

void mapSeeds(const fs::path& dir) {
  TargetMap map;
  map.descriptor = "eigen";
  map.fingerprint = "0123456789abcdef";
  map.descriptors = Eigen::MatrixXf::Random(3, 7);
  for (int i = 0; i < 3; ++i) {
    MapSegment s;
    s.centroid = Eigen::Vector3f(i, 2.0f * i, 0.5f);
    s.n_points = 40 + i;
    s.points = {Eigen::Vector3f(i, 0, 0), Eigen::Vector3f(0, i, 1)};
    map.segments.push_back(s);
  }
  fs::create_directories(dir);
  saveTargetMap(dir / "float16.map", map);
  saveTargetMap(dir / "float32.map", map, MapWriteOptions{false});
  for (const char* name : {"float16.map", "float32.map"}) withoutChecksum(dir / name);
}

void modelSeeds(const fs::path& dir) {
  fs::create_directories(dir);
#if SEMSEGMAP_WITH_TORCH
  // The smallest networks of each kind: the harness builds them at every run.
  NetConfig semsegmap_net;
  semsegmap_net.num_points = 64;
  semsegmap_net.pointnet_width = 2;
  semsegmap_net.descriptor_dim = 4;
  semsegmap_net.num_classes = 2;
  semsegmap_net.recon_grid = 4;
  NetConfig segmap_cnn = semsegmap_net;
  segmap_cnn.kind = DescriptorKind::kSegMapCnn;
  segmap_cnn.cnn_width = 1;
  segmap_cnn.grid_xy = 8;
  segmap_cnn.grid_z = 8;
  saveNet(dir / "semsegmap-net.model", *makeNet(semsegmap_net));
  saveNet(dir / "segmap-cnn.model", *makeNet(segmap_cnn));
#else
  Model model;
  model.fingerprint = "0123456789abcdef";
  writeModelFile(dir / "no-weights.model", model);
#endif
}

void trainingCacheSeeds(const fs::path& dir) {
  TrainingSet set;
  set.sources = {"sim:world=1,run=S0", "sim:world=1,run=S1"};
  set.source_worlds = {"world 1", "world 1"};
  for (uint16_t i = 0; i < 2; ++i) {
    TrainingObservation o;
    o.instance = i + 1;
    o.source = i;
    o.n_points = 3;
    o.purity = 0.9f;
    o.xyzhsv = std::vector<float>(18, 0.25f);
    o.classes = {1, 2, 3};
    o.modalities = {TrainingObservation::kHasColor | TrainingObservation::kHasClass, 0,
                    TrainingObservation::kHasColor};
    set.observations.push_back(o);
  }
  fs::create_directories(dir);
  writeTrainingCache(dir / "two.cache", set, "fuzz seed");
  withoutChecksum(dir / "two.cache");
}

// meta.yaml and frames.csv of a dataset written by DatasetWriter, joined as the harness reads.
void datasetSeeds(const fs::path& dir, const fs::path& scratch) {
  DatasetInfo info;
  info.name = "fuzz seed";
  info.rig = defaultSimRig();
  info.has_odometry = true;
  info.has_ground_truth_poses = true;
  {
    DatasetWriter writer(scratch / "dataset", info);
    for (size_t i = 0; i < 3; ++i) {
      Frame f;
      f.index = i;
      f.timestamp_s = 0.2 * i;
      f.points = somePoints(5);
      f.T_odom_base = Pose::Identity();
      f.T_world_base = Pose::Identity();
      writer.write(f);
    }
  }
  const std::string head = readText(scratch / "dataset/meta.yaml") + "\n--- frames.csv ---\n" +
                           readText(scratch / "dataset/frames.csv");
  writeText(dir / "three_frames", head);
  // With the files of the frames: frame 0's scan (and its labels, for meta.yaml to declare).
  const std::string scan = readText(scratch / "dataset/lidar" / frameFileName(0, "bin"));
  writeText(dir / "three_frames_with_scans", head + "\n--- lidar ---\n" + scan);
  const fs::path labels = scratch / "dataset/lidar_gt" / frameFileName(0, "bin");
  if (fs::exists(labels))
    writeText(dir / "three_frames_with_labels",
              head + "\n--- lidar ---\n" + scan + "\n--- labels ---\n" + readText(labels));
}

void kittiSeeds(const fs::path& calib_dir, const fs::path& scan_dir) {
  const std::string row =
      "7.215377e+02 0.000000e+00 6.095593e+02 4.485728e+01 0.000000e+00 "
      "7.215377e+02 1.728540e+02 2.163791e-01 0.000000e+00 0.000000e+00 "
      "1.000000e+00 2.745884e-03\n";
  writeText(calib_dir / "calib.txt", "P0: " + row + "P1: " + row + "P2: " + row + "P3: " + row +
                                         "Tr: 1 0 0 0.1 0 1 0 0.2 0 0 1 0.3\n");
  writeText(calib_dir / "velo_to_cam.txt",
            "calib_time: 15-Mar-2012 11:37:16\nR: 1 0 0 0 1 0 0 0 1\nT: 0.1 0.2 0.3\n"
            "S_rect_02: 1242 375\nR_rect_00: 1 0 0 0 1 0 0 0 1\nP_rect_02: " +
                row);
  writeText(calib_dir / "poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n");
  fs::create_directories(scan_dir);
  writeLidarBin(scan_dir / "scan.bin", somePoints(6));
  writeLabelBin(scan_dir / "scan.label", std::vector<PointLabel>(4, PointLabel{1, 7}));
}

void pointCloudSeeds(const fs::path& dir) {
  std::ostringstream pcd;
  pcd << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z intensity\n"
         "SIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\n"
         "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n";
  for (const LidarPoint& p : somePoints(3))
    pcd << p.x << ' ' << p.y << ' ' << p.z << ' ' << p.intensity << '\n';
  writeText(dir / "ascii.pcd", pcd.str());
  std::string binary = pcd.str();
  binary.replace(binary.find("DATA ascii"), std::string::npos, "DATA binary\n");
  const std::vector<LidarPoint> points = somePoints(3);
  binary.append(reinterpret_cast<const char*>(points.data()), points.size() * sizeof(LidarPoint));
  writeText(dir / "binary.pcd", binary);
  EnrichedCloud cloud;
  for (const LidarPoint& p : points) {
    EnrichedPoint e;
    e.x = p.x;
    e.y = p.y;
    e.z = p.z;
    cloud.push_back(e);
  }
  writeEnrichedPly(dir / "cloud.ply", cloud);
}

}  // namespace

#if SEMSEGMAP_WITH_ROS
namespace {

namespace rm = rosmsg;

rm::PointCloud2 someCloud() {
  rm::PointCloud2 cloud;
  cloud.header = {12.5, "lidar"};
  cloud.height = 1;
  cloud.width = 4;
  for (const char* name : {"x", "y", "z", "intensity"})
    cloud.fields.push_back({name, static_cast<uint32_t>(4 * cloud.fields.size()), 7, 1});
  cloud.point_step = 16;
  cloud.row_step = 64;
  const std::vector<LidarPoint> points = somePoints(4);
  const auto* bytes = reinterpret_cast<const uint8_t*>(points.data());
  cloud.data.assign(bytes, bytes + 64);
  return cloud;
}

rm::TfMessage someTf() {
  rm::TfMessage tf;
  tf.transforms.push_back({{1.0, "base_link"}, "lidar", {{0.1, 0.2, 0.3}, {0, 0, 0, 1}}});
  tf.transforms.push_back({{1.0, "odom"}, "base_link", {{1, 0, 0}, {0, 0, 0.6, 0.8}}});
  return tf;
}

// The harness's layout: a byte choosing the type (CDR: high bit set), then the message.
void rosMessageSeeds(const fs::path& dir) {
  rm::Image image{{1.0, "camera"}, 2, 2, "rgb8", 0, 6, std::vector<uint8_t>(12, 200)};
  rm::CompressedImage compressed{{1.0, "camera"}, "png", {}};
  rm::CameraInfo info{{1.0, "camera"},
                      480,
                      640,
                      "plumb_bob",
                      {0.1, 0.01, 0, 0, 0},
                      {500, 0, 320, 0, 500, 240, 0, 0, 1}};
  rm::Odometry odometry{{2.0, "odom"}, "base_link", {{1, 2, 0}, {0, 0, 0, 1}}};
  const std::string seeds[] = {toCdr(someCloud()), toCdr(image),    toCdr(compressed),
                               toCdr(info),        toCdr(odometry), toCdr(someTf())};
  for (size_t type = 0; type < 6; ++type)
    writeText(dir / ("cdr_" + std::to_string(type)),
              std::string(1, static_cast<char>(0x80 | type)) + seeds[type]);
}

// An unchunked MCAP file of one CDR channel (mcap.dev/spec), records written as the reader
// expects them: opcode, uint64 length, content.
void putRecord(BinaryWriter& file, uint8_t op, const BinaryWriter& content) {
  file.put(op);
  file.put(static_cast<uint64_t>(content.bytes().size()));
  file.putBytes(content.bytes().data(), content.bytes().size());
}

void bagStorageSeeds(const fs::path& dir) {
  const std::string magic("\x89MCAP0\r\n", 8);
  BinaryWriter f, header, schema, channel, message, data_end, footer;
  f.putBytes(magic.data(), magic.size());
  header.putString32("ros2");
  header.putString32("semsegmap fuzz seed");
  putRecord(f, 0x01, header);
  schema.put<uint16_t>(1);
  schema.putString32("sensor_msgs/msg/PointCloud2");
  schema.putString32("ros2msg");
  schema.putString32("");
  putRecord(f, 0x03, schema);
  channel.put<uint16_t>(1);
  channel.put<uint16_t>(1);
  channel.putString32("/points");
  channel.putString32("cdr");
  channel.put<uint32_t>(0);
  putRecord(f, 0x04, channel);
  message.put<uint16_t>(1);
  message.put<uint32_t>(0);
  message.put<uint64_t>(12500000000);
  message.put<uint64_t>(12500000000);
  const std::string cloud = toCdr(someCloud());
  message.putBytes(cloud.data(), cloud.size());
  putRecord(f, 0x05, message);
  data_end.put<uint32_t>(0);
  putRecord(f, 0x0F, data_end);
  footer.putBytes(std::string(20, '\0').data(), 20);
  putRecord(f, 0x02, footer);
  f.putBytes(magic.data(), magic.size());
  writeText(dir / "one_cloud.mcap", f.bytes());
  writeText(dir / "empty.bag", "#ROSBAG V2.0\n");
}

// fuzz_rosbag_sqlite's rows (its header says the layout): a cloud topic with two messages, as
// a .db3 alone and in a bag folder with its metadata.yaml.
std::string hex(const std::string& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (const char c : bytes) {
    const auto b = static_cast<unsigned char>(c);
    out += digits[b >> 4];
    out += digits[b & 15];
  }
  return out;
}

void sqliteBagSeeds(const fs::path& dir) {
  const std::string cloud = hex(toCdr(someCloud()));
  const std::string rows =
      "--8<--\ntopics|i1|t/points|tsensor_msgs/msg/PointCloud2|tcdr\n"
      "messages|i1|i1|i12500000000|x" +
      cloud + "\n" + "messages|i2|i1|i12600000000|x" + cloud + "\n";
  writeText(dir / "db3_only", rows);
  writeText(dir / "with_metadata",
            "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n"
            "  relative_file_paths:\n    - bag_0.db3\n  compression_format: \"\"\n" +
                rows);
}

}  // namespace
#endif

namespace {

// The project's own text files: the shipped configurations, class maps and example rig.
void copyTextSeeds(const fs::path& out, const fs::path& source) {
  for (const auto& entry : fs::directory_iterator(source / "config"))
    if (entry.path().extension() == ".yaml")
      writeText(out / "config" / entry.path().filename(), readText(entry.path()));
  for (const auto& entry : fs::directory_iterator(source / "config/class_maps"))
    writeText(out / "class_map" / entry.path().filename(), readText(entry.path()));
  writeText(out / "rig_file/pjlab.yaml", readText(source / "examples/pjlab/rig.yaml"));
}

void labelSetSeeds(const fs::path& dir, const fs::path& scratch) {
  LabelSetInfo info;
  info.frames = 12;
  info.cameras = 3;
  info.dataset = "sim:world=1";
  info.model = "mobilenet_seg.onnx";
  fs::create_directories(scratch / "labels");
  writeLabelSetInfo(scratch / "labels", info);
  writeText(dir / "labels.yaml", readText(scratch / "labels/labels.yaml"));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: make_seeds OUT_DIR SOURCE_DIR\n";
    return 2;
  }
  const fs::path out = argv[1], source = argv[2], scratch = out / ".scratch";
  try {
    fs::remove_all(out);
    mapSeeds(out / "map_file");
    modelSeeds(out / "model_file");
    trainingCacheSeeds(out / "training_cache");
    datasetSeeds(out / "dataset_dir", scratch);
    kittiSeeds(out / "kitti_calib", out / "kitti_scan");
    pointCloudSeeds(out / "point_cloud_file");
#if SEMSEGMAP_WITH_ROS
    rosMessageSeeds(out / "ros_messages");
    bagStorageSeeds(out / "rosbag_storage");
    sqliteBagSeeds(out / "rosbag_sqlite");
#endif
    copyTextSeeds(out, source);
    labelSetSeeds(out / "class_map", scratch);
    fs::remove_all(scratch);
  } catch (const std::exception& e) {
    std::cerr << "make_seeds: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
