// Bag storages (io/rosbag_storage.h): an input starting "#ROSBAG" as a ROS 1 .bag, any other
// as an MCAP file (.db3 bags: fuzz_rosbag_sqlite): its topics,
// the index of every topic's messages and the first few messages' bytes.
#include <algorithm>

#include "fuzz_input.h"
#include "semsegmap/io/rosbag_storage.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace semsegmap;
  const std::string_view text = fuzz::asText(data, size);
  const bool ros1 = text.substr(0, 7) == "#ROSBAG";
#if !SEMSEGMAP_WITH_ROS1
  if (ros1) return 0;
#endif
  const std::string name = ros1 ? "input.bag" : "input.mcap";
  const auto path = fuzz::writeInput(name, text);
  fuzz::expectCleanRefusal(name, [&] {
    auto bag = rosmsg::openBagStorage(path);
    for (const rosmsg::BagTopic& topic : bag->topics()) {
      const auto refs = bag->messages(topic.name);
      for (size_t i = 0; i < std::min<size_t>(refs.size(), 4); ++i)
        (void)bag->read(topic.name, refs[i]);
    }
  });
  return 0;
}
