// Little-endian encoding primitives for MCAP records. Private to dyad_mcap.
//
// ByteBuffer is an append-only byte array that keeps its capacity across Clear(), so the writer's
// per-message path never allocates once the chunk buffer has grown to the chunk size.
// ByteReader is a bounds-checked cursor: every getter returns false instead of reading past the end.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>

namespace dyad::mcap {

// MCAP is little-endian; encoding by memcpy keeps the hot path branch-free on x86-64 and arm64.
static_assert(std::endian::native == std::endian::little, "dyad_mcap assumes a little-endian host");

class ByteBuffer {
 public:
  ByteBuffer() = default;
  ByteBuffer(const ByteBuffer&) = delete;
  ByteBuffer& operator=(const ByteBuffer&) = delete;
  ByteBuffer(ByteBuffer&&) = default;
  ByteBuffer& operator=(ByteBuffer&&) = default;

  const std::uint8_t* data() const { return data_.get(); }
  std::uint8_t* data() { return data_.get(); }
  std::size_t size() const { return size_; }
  std::size_t capacity() const { return capacity_; }
  std::span<const std::uint8_t> span() const { return {data_.get(), size_}; }

  void Clear() { size_ = 0; }
  void Reserve(std::size_t capacity) {
    if (capacity > capacity_) Grow(capacity);
  }
  // Appends n uninitialised bytes and returns where they start.
  std::uint8_t* Extend(std::size_t n) {
    if (size_ + n > capacity_) Grow(size_ + n);
    std::uint8_t* p = data_.get() + size_;
    size_ += n;
    return p;
  }
  // Drops bytes from the end (e.g. to give back unused space reserved for compression).
  void Resize(std::size_t size) {
    Reserve(size);
    size_ = size;
  }

  void PutBytes(const void* p, std::size_t n) {
    if (n != 0) std::memcpy(Extend(n), p, n);
  }
  template <typename T>
  void Put(T v) {
    std::memcpy(Extend(sizeof(T)), &v, sizeof(T));
  }
  void PutU8(std::uint8_t v) { Put(v); }
  void PutU16(std::uint16_t v) { Put(v); }
  void PutU32(std::uint32_t v) { Put(v); }
  void PutU64(std::uint64_t v) { Put(v); }
  void PutString(std::string_view s) {
    PutU32(static_cast<std::uint32_t>(s.size()));
    PutBytes(s.data(), s.size());
  }
  void PutStringMap(const std::map<std::string, std::string>& map);
  // Overwrites a uint64 written earlier at `pos` (record lengths known only at the end).
  void PatchU64(std::size_t pos, std::uint64_t v) { std::memcpy(data_.get() + pos, &v, 8); }

  // Starts a record: writes the opcode and a length placeholder; returns the placeholder position.
  std::size_t BeginRecord(std::uint8_t opcode) {
    PutU8(opcode);
    std::size_t pos = size_;
    PutU64(0);
    return pos;
  }
  void EndRecord(std::size_t length_pos) { PatchU64(length_pos, size_ - length_pos - 8); }

 private:
  void Grow(std::size_t at_least);

  std::unique_ptr<std::uint8_t[]> data_;
  std::size_t size_ = 0;
  std::size_t capacity_ = 0;
};

class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> bytes) : p_(bytes.data()), end_(p_ + bytes.size()) {}

  std::size_t remaining() const { return static_cast<std::size_t>(end_ - p_); }
  const std::uint8_t* position() const { return p_; }

  template <typename T>
  bool Get(T* v) {
    if (remaining() < sizeof(T)) return false;
    std::memcpy(v, p_, sizeof(T));
    p_ += sizeof(T);
    return true;
  }
  bool Bytes(std::uint64_t n, std::span<const std::uint8_t>* out) {
    if (remaining() < n) return false;
    *out = {p_, static_cast<std::size_t>(n)};
    p_ += n;
    return true;
  }
  bool Skip(std::uint64_t n) {
    if (remaining() < n) return false;
    p_ += n;
    return true;
  }
  bool String(std::string* out) {
    std::uint32_t n = 0;
    std::span<const std::uint8_t> bytes;
    if (!Get(&n) || !Bytes(n, &bytes)) return false;
    out->assign(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    return true;
  }
  bool StringMap(std::map<std::string, std::string>* out);

 private:
  const std::uint8_t* p_;
  const std::uint8_t* end_;
};

}  // namespace dyad::mcap
