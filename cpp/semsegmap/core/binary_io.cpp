#include "semsegmap/core/binary_io.h"

#include <stdexcept>

#include "semsegmap/core/shown_text.h"
namespace semsegmap {

uint64_t fnv1a64(const void* data, size_t size, uint64_t seed) {
  const auto* p = static_cast<const unsigned char*>(data);
  uint64_t h = seed;
  for (size_t i = 0; i < size; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

void BinaryWriter::putString8(const std::string& s) {
  if (s.size() > 255)
    throw std::invalid_argument("string longer than 255 bytes: " + s.substr(0, 40) + "...");
  put<uint8_t>(static_cast<uint8_t>(s.size()));
  bytes_ += s;
}

void BinaryWriter::putString32(const std::string& s) {
  put<uint32_t>(static_cast<uint32_t>(s.size()));
  bytes_ += s;
}

BinaryReader::BinaryReader(std::filesystem::path path, std::string_view bytes, std::string format)
    : path_(std::move(path)), bytes_(bytes), format_(std::move(format)), end_(bytes.size()) {}

void BinaryReader::fail(const std::string& what) const {
  throw std::runtime_error(path_.string() + ": " + shownText(what, std::string::npos));
}

void BinaryReader::need(size_t count, size_t element_bytes, const char* field) const {
  if (element_bytes > 0 && count > remaining() / element_bytes)
    fail("truncated " + format_ + " (ends inside " + field + ")");
}

const char* BinaryReader::take(size_t size, const char* field) {
  need(size, 1, field);
  const char* p = bytes_.data() + at_;
  at_ += size;
  return p;
}

std::string BinaryReader::getString8(const char* field) {
  const size_t n = get<uint8_t>(field);
  return std::string(take(n, field), n);
}

std::string BinaryReader::getString32(const char* field) {
  const size_t n = get<uint32_t>(field);
  return std::string(take(n, field), n);
}

uint64_t BinaryReader::getCount(size_t min_element_bytes, const char* field) {
  const uint64_t n = get<uint64_t>(field);
  if (min_element_bytes > 0 && n > remaining() / min_element_bytes)
    fail("corrupt " + format_ + " (" + field + ": a count of " + std::to_string(n) +
         " does not fit in the rest of the file)");
  return n;
}

void BinaryReader::expectMagic(std::string_view magic) {
  if (remaining() < magic.size() || bytes_.substr(at_, magic.size()) != magic)
    fail("not a semsegmap " + format_ + " (bad magic)");
  at_ += magic.size();
}

void BinaryReader::checksummed() {
  if (end_ - at_ < sizeof(uint64_t)) fail("truncated " + format_ + " (no checksum)");
  end_ -= sizeof(uint64_t);
  uint64_t stored;
  std::memcpy(&stored, bytes_.data() + end_, sizeof stored);
  if (fnv1a64(bytes_.data(), end_, kProjectFnvSeed) != stored)
    fail("checksum mismatch: the " + format_ + " is truncated or corrupt");
}

void BinaryReader::expectEnd(const char* after) const {
  if (at_ != end_) fail("corrupt " + format_ + ": trailing bytes after " + after);
}

}  // namespace semsegmap
