// MCAP storage (ROS 2's default since Iron; `mcap convert` of ROS 1 bags): a sequence of records
// <opcode u8><length u64><content>, with Schema, Channel and Message records either directly in
// the data section or inside Chunks, compressed with zstd or lz4 (frame format) or not at all.
// Opening reads the file once, a chunk at a time, and keeps where each message is (its chunk and
// offset); reading a message decompresses its chunk, of which the last one is kept.
#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>
#include <stdexcept>

#include "semsegmap/core/binary_io.h"
#include "semsegmap/core/shown_text.h"
#include "semsegmap/io/rosbag_storage.h"

namespace semsegmap::rosmsg {
namespace {

namespace fs = std::filesystem;

constexpr char kMagic[] = "\x89MCAP0\r\n";
constexpr uint8_t kOpSchema = 0x03, kOpChannel = 0x04, kOpMessage = 0x05, kOpChunk = 0x06,
                  kOpDataEnd = 0x0F, kOpFooter = 0x02;

struct Channel {
  std::string topic;
  WireFormat format = WireFormat::kCdr;
  std::string encoding;
  size_t topic_index = 0;
};

struct ChunkPlace {
  uint64_t offset = 0;  // of the compressed records in the file
  uint64_t compressed_size = 0, uncompressed_size = 0;
  std::string compression;
};

class McapBag : public BagStorage {
 public:
  explicit McapBag(const fs::path& file);
  const fs::path& path() const override { return path_; }
  const std::vector<BagTopic>& topics() const override { return topics_; }
  std::vector<MessageRef> messages(const std::string& topic) override;
  SerializedMessage read(const std::string& topic, const MessageRef& ref) override;

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(path_.string() + ": " + shownText(what, std::string::npos));
  }
  std::string readAt(uint64_t offset, uint64_t size, const char* what);
  const std::string& chunk(size_t index);
  void indexChunk(uint64_t at, uint64_t length);
  // A Schema, Channel or Message record, in the data section (chunk 0, at a file offset) or in
  // chunk k > 0 (at an offset in its uncompressed records).
  void indexRecord(uint8_t op, std::string_view content, size_t chunk, uint64_t offset);

  fs::path path_;
  std::ifstream in_;
  uint64_t file_size_ = 0;
  std::map<uint16_t, std::string> schemas_;  // id -> type name
  std::map<uint16_t, Channel> channels_;
  std::vector<BagTopic> topics_;
  std::vector<std::vector<MessageRef>> refs_;  // per topic
  std::vector<ChunkPlace> chunks_;
  size_t cached_chunk_ = SIZE_MAX;
  std::string cached_;
};

McapBag::McapBag(const fs::path& file) : path_(file), in_(file, std::ios::binary) {
  if (!in_) fail("cannot open");
  in_.seekg(0, std::ios::end);
  file_size_ = static_cast<uint64_t>(in_.tellg());
  if (file_size_ < 8 || readAt(0, 8, "magic") != std::string(kMagic, 8))
    fail("not an MCAP file (bad magic)");
  uint64_t at = 8;
  while (at < file_size_) {
    const std::string head = readAt(at, 9, "a record header");
    const uint8_t op = static_cast<uint8_t>(head[0]);
    uint64_t length = 0;
    std::memcpy(&length, head.data() + 1, 8);
    if (length > file_size_ - at - 9) fail("truncated MCAP file (a record ends past the end)");
    if (op == kOpDataEnd || op == kOpFooter) break;  // the summary repeats what was seen
    if (op == kOpChunk) {
      indexChunk(at, length);
    } else if (op == kOpSchema || op == kOpChannel || op == kOpMessage) {
      // Of a message only its leading fields: channel, sequence, log time.
      const std::string content =
          readAt(at + 9, op == kOpMessage ? std::min<uint64_t>(length, 14) : length, "a record");
      indexRecord(op, content, 0, at);
    }
    at += 9 + length;
  }
  if (at < file_size_ && readAt(file_size_ - 8, 8, "magic") != std::string(kMagic, 8))
    fail("truncated MCAP file (no closing magic)");
}

void McapBag::indexChunk(uint64_t at, uint64_t length) {
  // The chunk's fields before its records; the records are read by chunk().
  const std::string head = readAt(at + 9, std::min<uint64_t>(length, 4096), "a chunk");
  BinaryReader r(path_, head, "MCAP chunk");
  r.get<uint64_t>("message_start_time");
  r.get<uint64_t>("message_end_time");
  ChunkPlace place;
  place.uncompressed_size = r.get<uint64_t>("uncompressed_size");
  r.get<uint32_t>("uncompressed_crc");
  place.compression = r.getString32("compression");
  place.compressed_size = r.get<uint64_t>("records");
  place.offset = at + 9 + r.position();
  // Compared without a sum, which a corrupt size would wrap around.
  if (place.compressed_size > at + 9 + length - place.offset)
    fail("corrupt MCAP chunk at byte " + std::to_string(at) + " (records past its end)");
  chunks_.push_back(place);
  const std::string& records = chunk(chunks_.size() - 1);
  for (uint64_t pos = 0; pos < records.size();) {
    BinaryReader rec(path_, std::string_view(records).substr(pos), "MCAP chunk record");
    const uint8_t op = rec.get<uint8_t>("opcode");
    const uint64_t len = rec.get<uint64_t>("length");
    const char* content = rec.take(len, "content");
    indexRecord(op, std::string_view(content, len), chunks_.size(), pos);
    pos += 9 + len;
  }
}

void McapBag::indexRecord(uint8_t op, std::string_view content, size_t chunk, uint64_t offset) {
  BinaryReader r(path_, content, "MCAP record");
  if (op == kOpSchema) {
    const uint16_t id = r.get<uint16_t>("schema id");
    schemas_[id] = normaliseTypeName(r.getString32("schema name"));
  } else if (op == kOpChannel) {
    const uint16_t id = r.get<uint16_t>("channel id");
    if (channels_.count(id)) return;  // repeated in later chunks
    const uint16_t schema = r.get<uint16_t>("schema id");
    Channel c;
    c.topic = r.getString32("topic");
    c.encoding = r.getString32("message_encoding");
    c.format = c.encoding == "ros1" ? WireFormat::kRos1 : WireFormat::kCdr;
    auto known = std::find_if(topics_.begin(), topics_.end(),
                              [&](const BagTopic& t) { return t.name == c.topic; });
    c.topic_index = static_cast<size_t>(known - topics_.begin());
    if (known == topics_.end()) {
      topics_.push_back(BagTopic{c.topic, schemas_.count(schema) ? schemas_[schema] : "", 0});
      refs_.emplace_back();
    }
    channels_[id] = c;
  } else if (op == kOpMessage) {
    const uint16_t id = r.get<uint16_t>("channel id");
    r.get<uint32_t>("sequence");
    const uint64_t log_time = r.get<uint64_t>("log_time");
    auto c = channels_.find(id);
    if (c == channels_.end())
      fail("corrupt MCAP file (a message on channel " + std::to_string(id) + ", never defined)");
    refs_[c->second.topic_index].push_back(
        MessageRef{static_cast<double>(log_time) * 1e-9, chunk, static_cast<int64_t>(offset)});
    ++topics_[c->second.topic_index].count;
  }
}

std::string McapBag::readAt(uint64_t offset, uint64_t size, const char* what) {
  if (size > file_size_ || offset > file_size_ - size)
    fail(std::string("truncated MCAP file (ends inside ") + what + ")");
  std::string bytes(size, '\0');
  in_.clear();
  in_.seekg(static_cast<std::streamoff>(offset));
  if (!in_.read(bytes.data(), static_cast<std::streamsize>(size)))
    fail(std::string("cannot read ") + what);
  return bytes;
}

const std::string& McapBag::chunk(size_t index) {
  if (index == cached_chunk_) return cached_;
  const ChunkPlace& c = chunks_.at(index);
  // A corrupt size must not allocate what the file cannot hold: no codec here expands a chunk
  // beyond this ratio.
  if (c.uncompressed_size > (c.compressed_size + 1024) * 1024)
    fail("corrupt MCAP chunk (uncompressed_size " + std::to_string(c.uncompressed_size) + ")");
  const std::string packed = readAt(c.offset, c.compressed_size, "a chunk");
  std::string out(c.uncompressed_size, '\0');
  cached_chunk_ = SIZE_MAX;
  if (c.compression.empty()) {
    out = packed;
  } else if (c.compression == "zstd") {
    const size_t n = ZSTD_decompress(out.data(), out.size(), packed.data(), packed.size());
    if (ZSTD_isError(n) || n != out.size())
      fail("corrupt MCAP chunk (zstd: " +
           std::string(ZSTD_isError(n) ? ZSTD_getErrorName(n) : "wrong size") + ")");
  } else if (c.compression == "lz4") {
    LZ4F_dctx* ctx = nullptr;
    LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION);
    size_t dst = out.size(), src = packed.size();
    const size_t rc = LZ4F_decompress(ctx, out.data(), &dst, packed.data(), &src, nullptr);
    LZ4F_freeDecompressionContext(ctx);
    // rc is 0 when the frame is complete; anything else is an error or a cut frame.
    if (LZ4F_isError(rc) || rc != 0 || dst != out.size())
      fail("corrupt MCAP chunk (lz4: " +
           std::string(LZ4F_isError(rc) ? LZ4F_getErrorName(rc) : "incomplete frame") + ")");
  } else {
    fail("MCAP chunk compression '" + c.compression + "' is not read (zstd, lz4 or none)");
  }
  if (out.size() != c.uncompressed_size) fail("corrupt MCAP chunk (size differs)");
  cached_ = std::move(out);
  cached_chunk_ = index;
  return cached_;
}

std::vector<MessageRef> McapBag::messages(const std::string& topic) {
  for (size_t t = 0; t < topics_.size(); ++t) {
    if (topics_[t].name != topic) continue;
    for (const auto& [id, c] : channels_)
      if (c.topic_index == t && c.encoding != "cdr" && c.encoding != "ros1")
        fail("topic " + topic + " is encoded as '" + c.encoding + "'; only cdr and ros1 are read");
    std::vector<MessageRef> refs = refs_[t];
    std::stable_sort(refs.begin(), refs.end(),
                     [](const MessageRef& a, const MessageRef& b) { return a.time_s < b.time_s; });
    return refs;
  }
  return {};
}

SerializedMessage McapBag::read(const std::string& topic, const MessageRef& ref) {
  std::string record;
  std::string_view view;
  if (ref.file == 0) {  // in the data section
    const std::string head = readAt(static_cast<uint64_t>(ref.row), 9, "a message");
    uint64_t length = 0;
    std::memcpy(&length, head.data() + 1, 8);
    record = readAt(static_cast<uint64_t>(ref.row) + 9, length, "a message");
    view = record;
  } else {
    const std::string& records = chunk(ref.file - 1);
    BinaryReader r(path_, std::string_view(records).substr(static_cast<size_t>(ref.row)),
                   "MCAP chunk");
    r.get<uint8_t>("opcode");
    const uint64_t length = r.get<uint64_t>("length");
    view = std::string_view(r.take(length, "message"), length);
  }
  BinaryReader r(path_, view, "MCAP message");
  const uint16_t id = r.get<uint16_t>("channel id");
  r.take(4 + 8 + 8, "message times");
  SerializedMessage m;
  m.bytes.assign(view.substr(r.position()));
  m.format = channels_.at(id).format;
  m.file = path_;
  m.topic = topic;
  return m;
}

}  // namespace

std::unique_ptr<BagStorage> openMcapBag(const std::filesystem::path& mcap_file) {
  return std::make_unique<McapBag>(mcap_file);
}

}  // namespace semsegmap::rosmsg
