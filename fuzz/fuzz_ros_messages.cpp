// ROS message decoding (io/ros_serialization.h, io/ros_decode.h): the first byte chooses the
// message type and the wire format (ROS 1 or CDR), the rest is the serialized message, which
// is parsed and then decoded as the bag reader does (points, pixels, lens, poses, TF).
#include <stdexcept>

#include "fuzz_input.h"
#include "semsegmap/io/ros_decode.h"
#include "semsegmap/io/ros_serialization.h"
#include "semsegmap/io/ros_tf.h"

namespace {

using namespace semsegmap::rosmsg;

void decode(int type, const SerializedMessage& m) {
  switch (type) {
    case 0:
      (void)decodePointCloud2(parsePointCloud2(m), "fuzz topic");
      break;
    case 1:
      (void)decodeImage(parseImage(m), "fuzz topic");
      break;
    case 2:
      (void)decodeCompressedImage(parseCompressedImage(m), "fuzz topic");
      break;
    case 3:
      (void)cameraFromInfo(parseCameraInfo(m), "fuzz topic");
      break;
    case 4:
      (void)stampedPoseOf(parseOdometry(m));
      break;
    case 5: {
      TfBuffer tf;
      const TfMessage msg = parseTfMessage(m);
      tf.add(msg, false);
      for (const TransformStamped& t : msg.transforms)
        (void)tf.lookup(t.header.frame_id, t.child_frame_id, 0.0);
      break;
    }
    default:
      (void)parseHeader(m);
  }
}

// The bag reader names the topic of the poses and transforms it refuses (std::invalid_argument).
void decodeAsTheReader(int type, const SerializedMessage& m) {
  try {
    decode(type, m);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(m.topic + ": " + e.what());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  SerializedMessage m;
  m.format = data[0] & 0x80 ? WireFormat::kCdr : WireFormat::kRos1;
  m.bytes.assign(reinterpret_cast<const char*>(data) + 1, size - 1);
  m.file = "fuzz.bag";
  m.topic = "fuzz topic";
  semsegmap::fuzz::expectCleanRefusal("fuzz topic",
                                      [&] { decodeAsTheReader((data[0] & 0x7f) % 7, m); });
  return 0;
}
