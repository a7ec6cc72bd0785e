// ROS 1 .bag files through rosbag_storage: the bag's index (read when it opens) gives each
// topic's messages; a message's bytes are read from its chunk when asked for, in ROS 1
// serialization, and parsed by io/ros_serialization.h.
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <rosbag/query.h>
#include <rosbag/view.h>

#include <cstring>
#include <fstream>
#include <map>
#include <stdexcept>

#include "semsegmap/io/rosbag_storage.h"

namespace semsegmap::rosmsg {
namespace {

namespace fs = std::filesystem;

// rosbag allocates each record's header and data lengths as it reads them (a corrupt length is
// 4 GB), and a chunk's buffer by the uncompressed size its header states, so the records are
// walked first: "#ROSBAG V2.0", then records of uint32 header length, header (fields of uint32
// length and "name=value"), uint32 data length, data, each of which must end inside the file. A
// chunk's data is itself such records: walked too when it is uncompressed; a compressed one
// (bz2, lz4) is only bounded by its size, as checking its records would mean unpacking it.
class RecordWalk {
 public:
  explicit RecordWalk(fs::path file) : file_(std::move(file)), in_(file_, std::ios::binary) {}

  void walkBag() {
    const uint64_t size = fs::file_size(file_);
    std::string version(13, '\0');
    if (!in_.read(version.data(), 13) || version != "#ROSBAG V2.0\n")
      throw std::runtime_error(file_.string() + ": not a ROS 1 bag of format 2.0");
    walk(13, size, false);
  }

 private:
  struct Header {
    int op = -1;
    std::string compression;
    int64_t size = -1;  // a chunk's uncompressed size
  };
  // A real record header holds a few short fields; a longer one is corrupt.
  static constexpr uint32_t kMaxHeaderBytes = 1 << 20;
  // A chunk unpacks to at most 1 GiB (rosbag writes 768 KiB chunks, larger only for one large
  // message); a compressed one beyond 64 MiB to at most 1000 times its size (bz2 of LiDAR and
  // camera data gains less than 10 times; below 64 MiB any ratio, as of a chunk of zeros).
  static constexpr uint64_t kMaxChunkBytes = uint64_t{1} << 30;
  static constexpr uint64_t kAnyRatioBytes = uint64_t{64} << 20;

  void walk(uint64_t at, uint64_t end, bool in_chunk) {
    while (at < end) {
      const uint64_t record = at;
      const uint32_t header_length = length(at, end, record, in_chunk);
      if (header_length > kMaxHeaderBytes)
        corrupt(record, "has a header of " + std::to_string(header_length) + " bytes");
      std::string bytes(header_length, '\0');
      in_.read(bytes.data(), header_length);
      const Header header = parse(bytes);
      at += 4 + header_length;
      const uint32_t data_length = length(at, end, record, in_chunk);
      if (!in_chunk && header.op == 0x05) checkChunk(record, header, at + 4, data_length);
      at += 4 + data_length;
    }
  }

  // The uint32 at `at`, which must be followed by that many bytes before `end`.
  uint32_t length(uint64_t at, uint64_t end, uint64_t record, bool in_chunk) {
    uint32_t value = 0;
    in_.seekg(static_cast<std::streamoff>(at));
    if (end - at < 4 || !in_.read(reinterpret_cast<char*>(&value), 4) || value > end - at - 4)
      corrupt(record, in_chunk ? "ends past the end of its chunk" : "ends past the end");
    return value;
  }

  void checkChunk(uint64_t record, const Header& h, uint64_t data, uint32_t data_length) {
    if (h.size < 0) corrupt(record, "is a chunk that does not say its size");
    const auto size = static_cast<uint64_t>(h.size);
    if (h.compression == "none") {
      if (size != data_length)
        corrupt(record, "is an uncompressed chunk of " + std::to_string(data_length) +
                            " bytes that says it holds " + std::to_string(size));
      walk(data, data + data_length, true);
    } else if (size > kMaxChunkBytes ||
               (size > kAnyRatioBytes && size > 1000 * uint64_t{data_length})) {
      corrupt(record, "is a chunk of " + std::to_string(data_length) +
                          " bytes that says it unpacks to " + std::to_string(size));
    }
  }

  // The fields of a record header; the ones the checks need are kept.
  Header parse(const std::string& bytes) const {
    Header h;
    for (size_t at = 0; at + 4 <= bytes.size();) {
      uint32_t n = 0;
      std::memcpy(&n, bytes.data() + at, 4);
      if (n > bytes.size() - at - 4) break;  // rosbag refuses such a header itself
      const std::string field = bytes.substr(at + 4, n);
      at += 4 + n;
      const size_t eq = field.find('=');
      if (eq == std::string::npos) continue;
      const std::string name = field.substr(0, eq), value = field.substr(eq + 1);
      if (name == "op" && value.size() == 1) h.op = static_cast<unsigned char>(value[0]);
      if (name == "compression") h.compression = value;
      if (name == "size" && value.size() == 4) {
        uint32_t size = 0;
        std::memcpy(&size, value.data(), 4);
        h.size = size;
      }
    }
    return h;
  }

  [[noreturn]] void corrupt(uint64_t record, const std::string& what) const {
    throw std::runtime_error(file_.string() + ": truncated or corrupt ROS 1 bag (the record at " +
                             "byte " + std::to_string(record) + " " + what +
                             "; an interrupted recording? `rosbag reindex` repairs it)");
  }

  fs::path file_;
  std::ifstream in_;
};

class Ros1Bag : public BagStorage {
 public:
  explicit Ros1Bag(const fs::path& file) : path_(file) {
    RecordWalk(file).walkBag();
    guard("not a readable ROS 1 bag", [&] {
      bag_.open(file.string(), rosbag::bagmode::Read);
      rosbag::View all(bag_);
      for (const rosbag::ConnectionInfo* c : all.getConnections()) {
        if (seen_.count(c->topic)) continue;
        seen_[c->topic] = topics_.size();
        topics_.push_back(BagTopic{c->topic, c->datatype, 0});
      }
      for (BagTopic& t : topics_) t.count = rosbag::View(bag_, rosbag::TopicQuery(t.name)).size();
    });
  }
  const fs::path& path() const override { return path_; }
  const std::vector<BagTopic>& topics() const override { return topics_; }

  std::vector<MessageRef> messages(const std::string& topic) override {
    std::vector<MessageRef> refs;
    if (!seen_.count(topic)) return refs;
    guard("corrupt ROS 1 bag", [&] {
      std::vector<rosbag::MessageInstance>& kept = instances_[topic];
      kept.clear();
      rosbag::View view(bag_, rosbag::TopicQuery(topic));
      for (const rosbag::MessageInstance& m : view) {
        refs.push_back(MessageRef{m.getTime().toSec(), 0, static_cast<int64_t>(kept.size())});
        kept.push_back(m);  // the index entry and connection only, no message data
      }
    });
    return refs;
  }

  SerializedMessage read(const std::string& topic, const MessageRef& ref) override {
    SerializedMessage out;
    out.format = WireFormat::kRos1;
    out.file = path_;
    out.topic = topic;
    guard("corrupt ROS 1 bag", [&] {
      const rosbag::MessageInstance& m = instances_.at(topic).at(static_cast<size_t>(ref.row));
      out.bytes.resize(m.size());
      ros::serialization::OStream stream(reinterpret_cast<uint8_t*>(out.bytes.data()),
                                         static_cast<uint32_t>(out.bytes.size()));
      m.write(stream);
    });
    return out;
  }

 private:
  // rosbag and roscpp report problems as exceptions of their own; each becomes one line naming
  // the file, with the advice for the one common case of an interrupted recording.
  template <typename F>
  void guard(const char* what, F&& body) {
    try {
      body();
    } catch (const rosbag::BagUnindexedException&) {
      throw std::runtime_error(path_.string() + ": " + what +
                               " (unindexed: the recording was interrupted; `rosbag reindex` "
                               "repairs it)");
    } catch (const std::exception& e) {  // ros::Exception, and what boost throws beneath
      throw std::runtime_error(path_.string() + ": " + what + " (" + e.what() + ")");
    }
  }

  fs::path path_;
  rosbag::Bag bag_;
  std::vector<BagTopic> topics_;
  std::map<std::string, size_t> seen_;
  std::map<std::string, std::vector<rosbag::MessageInstance>> instances_;
};

}  // namespace

std::unique_ptr<BagStorage> openRos1Bag(const std::filesystem::path& bag_file) {
  return std::make_unique<Ros1Bag>(bag_file);
}

}  // namespace semsegmap::rosmsg
