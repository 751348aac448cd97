#include "wire.hpp"

#include <algorithm>

namespace dyad::mcap {

void ByteBuffer::Grow(std::size_t at_least) {
  // Doubling keeps appends amortised O(1) while the buffer warms up.
  std::size_t capacity = std::max<std::size_t>({at_least, capacity_ * 2, 256});
  auto bigger = std::make_unique_for_overwrite<std::uint8_t[]>(capacity);
  if (size_ != 0) std::memcpy(bigger.get(), data_.get(), size_);
  data_ = std::move(bigger);
  capacity_ = capacity;
}

void ByteBuffer::PutStringMap(const std::map<std::string, std::string>& map) {
  std::size_t length_pos = size_;
  PutU32(0);
  for (const auto& [key, value] : map) {
    PutString(key);
    PutString(value);
  }
  auto length = static_cast<std::uint32_t>(size_ - length_pos - 4);
  std::memcpy(data_.get() + length_pos, &length, 4);
}

bool ByteReader::StringMap(std::map<std::string, std::string>* out) {
  std::uint32_t n = 0;
  std::span<const std::uint8_t> bytes;
  if (!Get(&n) || !Bytes(n, &bytes)) return false;
  ByteReader entries(bytes);
  out->clear();
  while (entries.remaining() > 0) {
    std::string key, value;
    if (!entries.String(&key) || !entries.String(&value)) return false;
    (*out)[std::move(key)] = std::move(value);
  }
  return true;
}

}  // namespace dyad::mcap
