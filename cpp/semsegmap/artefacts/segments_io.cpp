#include "semsegmap/artefacts/segments_io.h"

#include <cstring>
#include <iomanip>
#include <ostream>
#include <string>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/io/ply_writer.h"

namespace semsegmap {

void writeSegmentsCsv(const std::filesystem::path& path, const std::vector<Segment>& segments,
                      const ClassTable& classes, bool has_ground_truth,
                      const std::vector<std::optional<size_t>>& frame_numbers) {
  const auto number = [&](size_t frame) {
    return frame < frame_numbers.size() && frame_numbers[frame]
               ? std::to_string(*frame_numbers[frame])
               : std::string();
  };
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "id,observations,points,centroid_x,centroid_y,centroid_z,class,first_frame,last_frame,"
           "first_dataset_frame,last_dataset_frame,gt_instance,gt_purity\n";
    out << std::fixed;
    for (const auto& s : segments) {
      const SegmentObservation& o = s.last();
      const std::string cls =
          classes.contains(o.majority_class) ? classes.at(o.majority_class).name : "unknown";
      out << s.id << ',' << s.observations.size() << ',' << o.n_points << ','
          << std::setprecision(3) << o.centroid.x() << ',' << o.centroid.y() << ','
          << o.centroid.z() << ',' << cls << ',' << s.first_frame << ',' << s.last_frame << ','
          << number(s.first_frame) << ',' << number(s.last_frame) << ',';
      if (has_ground_truth)
        out << o.gt_instance << ',' << std::setprecision(4) << o.gt_purity;
      else
        out << ',';
      out << '\n';
    }
  });
}

void writeSegmentPointsPly(const std::filesystem::path& path,
                           const std::vector<Segment>& segments) {
  size_t n = 0;
  for (const auto& s : segments) n += s.last().points.size();
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "ply\nformat binary_little_endian 1.0\nelement vertex " << n
        << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
           "property uchar green\nproperty uchar blue\nproperty ushort class\nproperty int "
           "segment\n"
           "end_header\n";
    char record[12 + 3 + 2 + 4];
    for (const auto& s : segments) {
      const int32_t id = static_cast<int32_t>(s.id);
      for (const auto& p : s.last().points) {
        uint8_t rgb[3] = {0, 0, 0};
        if (p.has_color) hsvToRgb(p.h, p.s, p.v, rgb[0], rgb[1], rgb[2]);
        std::memcpy(record, &p.x, 4);
        std::memcpy(record + 4, &p.y, 4);
        std::memcpy(record + 8, &p.z, 4);
        std::memcpy(record + 12, rgb, 3);
        std::memcpy(record + 15, &p.class_id, 2);
        std::memcpy(record + 17, &id, 4);
        out.write(record, sizeof(record));
      }
    }
  });
}

}  // namespace semsegmap
