// ROS 2 bags in SQLite storage (io/rosbag_sqlite.cpp): the SQLite file format is SQLite's own
// and fuzzed by its authors, so mutated database bytes would only test that. What the reader
// trusts is the content of the tables a bag writer left: this harness builds a database with
// the bag's tables from the input's rows, of any value type (NULLs, text ids, blobs as names),
// and a metadata.yaml, then reads the bag as the bag reader does.
//
// The input: metadata.yaml's text (empty: none), a line "--8<--", then one row a line,
// "topics|id|name|type|serialization_format" or "messages|id|topic_id|timestamp|data"; a value
// is "i<integer>", "f<real>", "x<hex blob>", "n" (NULL) or text.
#include <algorithm>

#include "fuzz_input.h"
#include "semsegmap/io/rosbag_storage.h"
#include "sqlite_bag_rows.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace semsegmap;
  const auto [metadata, rows] = fuzz::splitAt(fuzz::asText(data, size), "--8<--\n");
  namespace fs = std::filesystem;
  const fs::path bag = fuzz::scratch() / "bag";
  fs::remove_all(bag);
  fs::create_directories(bag);
  fuzz::writeBagDatabase(bag / "bag_0.db3", rows);
  if (!metadata.empty()) fuzz::writeInput("bag/metadata.yaml", metadata);
  const fs::path opened = metadata.empty() ? bag / "bag_0.db3" : bag;
  fuzz::expectCleanRefusal(bag.string(), [&] {
    auto storage = rosmsg::openBagStorage(opened);
    for (const rosmsg::BagTopic& topic : storage->topics()) {
      const auto refs = storage->messages(topic.name);
      for (size_t i = 0; i < std::min<size_t>(refs.size(), 4); ++i) {
        (void)storage->read(topic.name, refs[i]);
        (void)storage->readPrefix(topic.name, refs[i], 16);
      }
    }
  });
  return 0;
}
