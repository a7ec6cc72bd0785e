// ROS 1 .bag files through rosbag_storage: the bag's index (read when it opens) gives each
// topic's messages; a message's bytes are read from its chunk when asked for, in ROS 1
// serialization, and parsed by io/ros_serialization.h.
#include <ros/serialization.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <rosbag/query.h>
#include <rosbag/view.h>

#include <fstream>
#include <map>
#include <stdexcept>

#include "semsegmap/io/rosbag_storage.h"

namespace semsegmap::rosmsg {
namespace {

namespace fs = std::filesystem;

// rosbag allocates each record's header and data lengths as it reads them (a corrupt length is
// 4 GB), so the records' lengths are walked first: "#ROSBAG V2.0", then records of uint32 header
// length, header, uint32 data length, data, each of which must end inside the file.
void checkRecordLengths(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  const uint64_t size = fs::file_size(file);
  std::string version(13, '\0');
  if (!in.read(version.data(), 13) || version != "#ROSBAG V2.0\n")
    throw std::runtime_error(file.string() + ": not a ROS 1 bag of format 2.0");
  for (uint64_t at = 13; at < size;) {
    const uint64_t record = at;
    for (int part = 0; part < 2; ++part) {  // the header, then the data
      uint32_t length = 0;
      if (size - at < 4 || !in.read(reinterpret_cast<char*>(&length), 4) || length > size - at - 4)
        throw std::runtime_error(file.string() +
                                 ": truncated or corrupt ROS 1 bag (the record at " + "byte " +
                                 std::to_string(record) + " ends past the end; an " +
                                 "interrupted recording? `rosbag reindex` repairs it)");
      at += 4 + length;
      in.seekg(static_cast<std::streamoff>(at));
    }
  }
}

class Ros1Bag : public BagStorage {
 public:
  explicit Ros1Bag(const fs::path& file) : path_(file) {
    checkRecordLengths(file);
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
