#include "semsegmap/io/ros_serialization.h"

#include <cmath>
#include <memory>
#include <stdexcept>

#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <fastcdr/exceptions/Exception.h>

#include "semsegmap/core/binary_io.h"
#include "semsegmap/core/shown_text.h"

namespace semsegmap::rosmsg {
namespace {

namespace cdr = eprosima::fastcdr;

// Each message layout is written once, as a visit of its fields in wire order, and run by a
// reader of either wire format or by the CDR writer. The formats differ only in the Header (ROS 1
// has a sequence number and unsigned seconds) and in alignment, which fastcdr does.

// ROS 1: packed little-endian, strings and sequences prefixed by a uint32 length; every read is
// bounds-checked by the project's BinaryReader, so truncation names the field.
class Ros1Reader {
 public:
  Ros1Reader(const SerializedMessage& m, const std::string& what)
      : in_(m.file, m.bytes, what + " message on " + m.topic) {}
  static constexpr bool kReading = true;
  bool ros1() const { return true; }
  void u8(uint8_t& v, const char* f) { v = in_.get<uint8_t>(f); }
  void u32(uint32_t& v, const char* f) { v = in_.get<uint32_t>(f); }
  void f64(double& v, const char* f) { v = in_.get<double>(f); }
  void boolean(bool& v, const char* f) { v = in_.get<uint8_t>(f) != 0; }
  void str(std::string& v, const char* f) {
    const size_t n = count(1, f);
    v.assign(in_.take(n, f), n);
  }
  void bytes(std::vector<uint8_t>& v, const char* f) { v = in_.getArray<uint8_t>(count(1, f), f); }
  void stamp(double& s, const char* f) {
    const uint32_t sec = in_.get<uint32_t>(f), nsec = in_.get<uint32_t>(f);
    s = sec + nsec * 1e-9;
  }
  // A sequence length, refused when the rest of the message cannot hold that many elements.
  size_t count(size_t min_element_bytes, const char* f) {
    const uint32_t n = in_.get<uint32_t>(f);
    in_.need(n, min_element_bytes, f);
    return n;
  }

 private:
  BinaryReader in_;
};

// CDR (ROS 2): fastcdr reads with alignment and the encapsulation's byte order; running out of
// bytes is reported as truncation at the field being read.
class CdrReader {
 public:
  CdrReader(const SerializedMessage& m, const std::string& what)
      : msg_(m),
        what_(what),
        buffer_(const_cast<char*>(m.bytes.data()), m.bytes.size()),
        in_(buffer_, cdr::Cdr::DEFAULT_ENDIAN, cdr::Cdr::DDS_CDR) {
    guard("encapsulation", [&] { in_.read_encapsulation(); });
  }
  static constexpr bool kReading = true;
  bool ros1() const { return false; }
  void u8(uint8_t& v, const char* f) {
    guard(f, [&] { in_.deserialize(v); });
  }
  void u32(uint32_t& v, const char* f) {
    guard(f, [&] { in_.deserialize(v); });
  }
  void f64(double& v, const char* f) {
    guard(f, [&] { in_.deserialize(v); });
  }
  void boolean(bool& v, const char* f) {
    uint8_t b = 0;
    u8(b, f);
    v = b != 0;
  }
  void str(std::string& v, const char* f) {
    guard(f, [&] { in_.deserialize(v); });
  }
  void bytes(std::vector<uint8_t>& v, const char* f) {
    v.resize(count(1, f));
    guard(f, [&] { in_.deserializeArray(v.data(), v.size()); });
  }
  void stamp(double& s, const char* f) {
    int32_t sec = 0;
    uint32_t nsec = 0;
    guard(f, [&] { in_.deserialize(sec).deserialize(nsec); });
    s = sec + nsec * 1e-9;
  }
  size_t count(size_t min_element_bytes, const char* f) {
    uint32_t n = 0;
    u32(n, f);
    const size_t left =
        static_cast<size_t>(msg_.bytes.data() + msg_.bytes.size() - in_.getCurrentPosition());
    // As the ROS 1 reader says it: a length beyond the bytes left is a truncated message.
    if (static_cast<uint64_t>(n) * min_element_bytes > left)
      fail("truncated " + what_ + " message on " + msg_.topic + " (ends inside " + f + ")");
    return n;
  }

 private:
  template <typename F>
  void guard(const char* f, F&& read) {
    try {
      read();
    } catch (const cdr::exception::Exception&) {
      fail("truncated " + what_ + " message on " + msg_.topic + " (ends inside " + f + ")");
    }
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(msg_.file.string() + ": " + shownText(what, std::string::npos));
  }

  const SerializedMessage& msg_;
  std::string what_;
  cdr::FastBuffer buffer_;
  cdr::Cdr in_;
};

// The CDR writer of the tests' ROS 2 fixtures: little-endian, as ROS 2 on x86 writes it. fastcdr
// skips alignment padding without writing it, so the writer fills a zeroed buffer of the size a
// first, measuring pass found: the bytes are the same every time.
class CdrWriter {
 public:
  explicit CdrWriter(size_t size = 0)
      : storage_(size, '\0'),
        buffer_(size == 0 ? growing_ : fixed(storage_)),
        out_(buffer_, cdr::Cdr::LITTLE_ENDIANNESS, cdr::Cdr::DDS_CDR) {
    out_.serialize_encapsulation();
  }
  static constexpr bool kReading = false;
  bool ros1() const { return false; }
  void u8(uint8_t& v, const char*) { out_.serialize(v); }
  void u32(uint32_t& v, const char*) { out_.serialize(v); }
  void f64(double& v, const char*) { out_.serialize(v); }
  void boolean(bool& v, const char*) { out_.serialize(static_cast<uint8_t>(v ? 1 : 0)); }
  void str(std::string& v, const char*) { out_.serialize(v); }
  void bytes(std::vector<uint8_t>& v, const char*) {
    out_.serialize(static_cast<uint32_t>(v.size()));
    out_.serializeArray(v.data(), v.size());
  }
  void stamp(double& s, const char*) {
    int32_t sec = static_cast<int32_t>(std::floor(s));
    int64_t nsec = std::llround((s - sec) * 1e9);
    if (nsec >= 1000000000) ++sec, nsec -= 1000000000;  // rounding up to the next second
    out_.serialize(sec).serialize(static_cast<uint32_t>(nsec));
  }
  void writeCount(size_t n) { out_.serialize(static_cast<uint32_t>(n)); }
  size_t size() const { return out_.getSerializedDataLength(); }
  std::string take() { return storage_.substr(0, size()); }

 private:
  cdr::FastBuffer& fixed(std::string& s) {
    fixed_ = std::make_unique<cdr::FastBuffer>(s.data(), s.size());
    return *fixed_;
  }
  std::string storage_;
  cdr::FastBuffer growing_;
  std::unique_ptr<cdr::FastBuffer> fixed_;
  cdr::FastBuffer& buffer_;
  cdr::Cdr out_;
};

// A sequence of messages: its length, then each element visited.
template <class IO, typename T, typename Visit>
void sequence(IO& io, std::vector<T>& v, size_t min_element_bytes, const char* f, Visit&& each) {
  if constexpr (IO::kReading) {
    v.resize(io.count(min_element_bytes, f));
  } else {
    io.writeCount(v.size());
  }
  for (T& e : v) each(e);
}

template <class IO>
void visit(IO& io, Header& h) {
  if (io.ros1()) {
    uint32_t seq = 0;  // ROS 1 only; nothing here uses it
    io.u32(seq, "header.seq");
  }
  io.stamp(h.stamp_s, "header.stamp");
  io.str(h.frame_id, "header.frame_id");
}

template <class IO>
void visit(IO& io, PointCloud2& m) {
  visit(io, m.header);
  io.u32(m.height, "height");
  io.u32(m.width, "width");
  sequence(io, m.fields, 13, "fields", [&](PointField& p) {
    io.str(p.name, "fields.name");
    io.u32(p.offset, "fields.offset");
    io.u8(p.datatype, "fields.datatype");
    io.u32(p.count, "fields.count");
  });
  io.boolean(m.is_bigendian, "is_bigendian");
  io.u32(m.point_step, "point_step");
  io.u32(m.row_step, "row_step");
  io.bytes(m.data, "data");
  io.boolean(m.is_dense, "is_dense");
}

template <class IO>
void visit(IO& io, Image& m) {
  visit(io, m.header);
  io.u32(m.height, "height");
  io.u32(m.width, "width");
  io.str(m.encoding, "encoding");
  io.u8(m.is_bigendian, "is_bigendian");
  io.u32(m.step, "step");
  io.bytes(m.data, "data");
}

template <class IO>
void visit(IO& io, CompressedImage& m) {
  visit(io, m.header);
  io.str(m.format, "format");
  io.bytes(m.data, "data");
}

template <class IO>
void visit(IO& io, CameraInfo& m) {
  visit(io, m.header);
  io.u32(m.height, "height");
  io.u32(m.width, "width");
  io.str(m.distortion_model, "distortion_model");
  sequence(io, m.D, 8, "D", [&](double& d) { io.f64(d, "D"); });
  for (double& k : m.K) io.f64(k, "K");
  // R, P, binning and region of interest follow; the reader takes the raw camera's K and D. The
  // writer fills them (identity R, zeros) so that the fixture is a whole message.
  if constexpr (!IO::kReading) {
    for (int i = 0; i < 9 + 12; ++i) {
      double v = i < 9 && i % 4 == 0 ? 1.0 : 0.0;
      io.f64(v, "");
    }
    uint32_t zero = 0;
    for (int i = 0; i < 2 + 4; ++i) io.u32(zero, "");
    bool do_rectify = false;
    io.boolean(do_rectify, "");
  }
}

template <class IO>
void visit(IO& io, Transform& t, const char* f) {
  for (double& v : t.translation) io.f64(v, f);
  for (double& v : t.rotation) io.f64(v, f);
}

template <class IO>
void visit(IO& io, Odometry& m) {
  visit(io, m.header);
  io.str(m.child_frame_id, "child_frame_id");
  visit(io, m.pose, "pose.pose");
  // Covariance and twist follow; unused. The writer fills them with zeros so a ROS 2 tool can
  // read the fixture.
  if constexpr (!IO::kReading) {
    double zero = 0;
    for (int i = 0; i < 36 + 6 + 36; ++i) io.f64(zero, "");
  }
}

template <class IO>
void visit(IO& io, TfMessage& m) {
  sequence(io, m.transforms, 8, "transforms", [&](TransformStamped& t) {
    visit(io, t.header);
    io.str(t.child_frame_id, "transforms.child_frame_id");
    visit(io, t.transform, "transforms.transform");
  });
}

template <typename M>
M parse(const SerializedMessage& m, const char* type) {
  M out;
  if (m.format == WireFormat::kRos1) {
    Ros1Reader in(m, type);
    visit(in, out);
  } else {
    CdrReader in(m, type);
    visit(in, out);
  }
  return out;
}

template <typename M>
std::string write(const M& m) {
  M copy = m;  // the visit takes fields by reference for reading and writing alike
  CdrWriter measure;
  visit(measure, copy);
  CdrWriter out(measure.size());
  visit(out, copy);
  return out.take();
}

}  // namespace

Header parseHeader(const SerializedMessage& m) {
  return parse<Header>(m, "std_msgs/Header");
}
PointCloud2 parsePointCloud2(const SerializedMessage& m) {
  return parse<PointCloud2>(m, kPointCloud2);
}
Image parseImage(const SerializedMessage& m) {
  return parse<Image>(m, kImage);
}
CompressedImage parseCompressedImage(const SerializedMessage& m) {
  return parse<CompressedImage>(m, kCompressedImage);
}
CameraInfo parseCameraInfo(const SerializedMessage& m) {
  return parse<CameraInfo>(m, kCameraInfo);
}
Odometry parseOdometry(const SerializedMessage& m) {
  return parse<Odometry>(m, kOdometry);
}
TfMessage parseTfMessage(const SerializedMessage& m) {
  return parse<TfMessage>(m, kTfMessage);
}

std::string toCdr(const PointCloud2& m) {
  return write(m);
}
std::string toCdr(const Image& m) {
  return write(m);
}
std::string toCdr(const CompressedImage& m) {
  return write(m);
}
std::string toCdr(const CameraInfo& m) {
  return write(m);
}
std::string toCdr(const Odometry& m) {
  return write(m);
}
std::string toCdr(const TfMessage& m) {
  return write(m);
}

}  // namespace semsegmap::rosmsg
