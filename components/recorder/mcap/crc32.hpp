// CRC32 (IEEE 802.3 / zlib polynomial), the checksum MCAP uses. Private to dyad_mcap.
//
// Backed by zlib's crc32_z: zlib 1.2.13 (Debian 12) computes several bytes per step ("braided"),
// several times faster than a byte-at-a-time table, and zlib1g is on every Debian system anyway.
// Incremental: Crc32(Crc32(0, a), b) == Crc32(0, a + b).
#pragma once

#include <cstddef>
#include <cstdint>

#include <zlib.h>

namespace dyad::mcap {

inline std::uint32_t Crc32(std::uint32_t crc, const void* data, std::size_t size) {
  return static_cast<std::uint32_t>(
      crc32_z(crc, static_cast<const Bytef*>(data), static_cast<z_size_t>(size)));
}

}  // namespace dyad::mcap
