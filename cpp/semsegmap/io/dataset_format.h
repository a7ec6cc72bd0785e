// The project's dataset directory format (docs/dataset-format.md): meta.yaml, frames.csv,
// lidar/, lidar_gt/, camK/, camK_label/. This header holds the pieces shared by the reader
// and the writer.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "semsegmap/core/exact_text.h"  // formatExactDouble, for the writers
#include "semsegmap/core/frame_source.h"

namespace semsegmap {

constexpr int kDatasetFormatVersion = 1;

// File name of frame `index` inside a subfolder, e.g. lidar/000042.bin.
std::string frameFileName(size_t index, const std::string& extension);

// First line of frames.csv; the reader requires it verbatim.
extern const char* const kFramesCsvHeader;

// Throw std::runtime_error "<path>: ..." when a label uses a class id that `classes` lacks, so a
// dataset never holds ids that ClassTable::at cannot look up later in the pipeline.
void checkLabelClasses(const std::filesystem::path& path, const std::vector<PointLabel>& labels,
                       const ClassTable& classes);
void checkLabelClasses(const std::filesystem::path& path, const Image& label_image,
                       const ClassTable& classes);

// meta.yaml <-> DatasetInfo (sensor rig with intrinsics and LiDAR-to-camera extrinsics, class
// table, frame rate, flags). Reading checks the format version and every field; unknown keys
// and missing fields throw std::runtime_error "<path>: <field>: <what was wrong>".
void writeMetaYaml(const std::filesystem::path& path, const DatasetInfo& info);
DatasetInfo readMetaYaml(const std::filesystem::path& path);

// "640x480": an image size in the errors of the reader and the writer.
std::string imageSizeText(int width, int height);

// LiDAR scan as float32 x y z intensity (KITTI .bin layout).
void writeLidarBin(const std::filesystem::path& path, const std::vector<LidarPoint>& points);
std::vector<LidarPoint> readLidarBin(const std::filesystem::path& path);

// Per-point times (seconds after the frame's timestamp) as float32, one per point of the scan:
// lidar_times/NNNNNN.bin, present when the source had them (for deskewing).
void writePointTimesBin(const std::filesystem::path& path, const std::vector<float>& times);
std::vector<float> readPointTimesBin(const std::filesystem::path& path);

// Per-point labels as uint32: class in the low 16 bits, instance in the high 16
// (SemanticKITTI's .label layout).
void writeLabelBin(const std::filesystem::path& path, const std::vector<PointLabel>& labels);
std::vector<PointLabel> readLabelBin(const std::filesystem::path& path);

}  // namespace semsegmap
