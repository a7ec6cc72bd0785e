// The one binary reader and writer of every file format (maps, models, training caches): plain
// little-endian values appended to a byte string, read back with a bound check before every
// read, so that a truncated or corrupt file fails with "<file>: truncated <format> (ends inside
// <field>)" instead of reading past the end or allocating what a corrupt count says.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace semsegmap {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the file formats are little-endian");

// FNV-1a, 64 bit, from the standard offset basis or from `seed` (chaining: the hash of b after a
// equals the hash of a + b).
constexpr uint64_t kFnvOffsetBasis = 14695981039346656037ull;
uint64_t fnv1a64(const void* data, size_t size, uint64_t seed = kFnvOffsetBasis);

// The start of the file formats' checksums and of the training split's object keys: the standard
// basis with its last digit lost when the first map files were written. It is as good a start
// for catching corruption, and changing it would refuse every saved map and move objects between
// training and validation, so it stays.
constexpr uint64_t kProjectFnvSeed = 1469598103934665603ull;

class BinaryWriter {
 public:
  template <typename T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void putBytes(const void* data, size_t size) {
    bytes_.append(static_cast<const char*>(data), size);
  }
  template <typename T>
  void putArray(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    putBytes(v.data(), v.size() * sizeof(T));
  }
  // A length-prefixed string: uint8 (throws std::invalid_argument beyond 255 bytes) or uint32.
  void putString8(const std::string& s);
  void putString32(const std::string& s);
  // Appends the FNV-1a of every byte so far (readers check it with BinaryReader::checksummed).
  void putChecksum() { put<uint64_t>(fnv1a64(bytes_.data(), bytes_.size(), kProjectFnvSeed)); }

  const std::string& bytes() const { return bytes_; }
  std::string take() { return std::move(bytes_); }

 private:
  std::string bytes_;
};

class BinaryReader {
 public:
  // `format` names the kind of file in messages ("map file", "model file", "training cache").
  // `bytes` must outlive the reader.
  BinaryReader(std::filesystem::path path, std::string_view bytes, std::string format);

  template <typename T>
  T get(const char* field) {
    static_assert(std::is_trivially_copyable_v<T>);
    T v;
    std::memcpy(&v, take(sizeof(T), field), sizeof(T));
    return v;
  }
  // `n` elements of T; the length is checked before anything is allocated.
  template <typename T>
  std::vector<T> getArray(size_t n, const char* field) {
    static_assert(std::is_trivially_copyable_v<T>);
    need(n, sizeof(T), field);
    std::vector<T> v(n);
    if (n > 0) std::memcpy(v.data(), take(n * sizeof(T), field), n * sizeof(T));
    return v;
  }
  std::string getString8(const char* field);
  std::string getString32(const char* field);
  // A count of elements of at least `min_element_bytes` each: more than the rest of the file
  // could hold is corrupt, found before the caller allocates.
  uint64_t getCount(size_t min_element_bytes, const char* field);
  // Compares the leading bytes with `magic`.
  void expectMagic(std::string_view magic);
  const char* take(size_t size, const char* field);
  void need(size_t count, size_t element_bytes, const char* field) const;

  // The trailing uint64 FNV-1a of everything before it: checked, then excluded from reading.
  void checksummed();
  void expectEnd(const char* after) const;  // "trailing bytes after <after>"
  size_t position() const { return at_; }
  size_t remaining() const { return end_ - at_; }
  [[noreturn]] void fail(const std::string& what) const;  // "<path>: <what>"
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::string_view bytes_;
  std::string format_;
  size_t at_ = 0, end_ = 0;
};

}  // namespace semsegmap
