// Constants of the MCAP file format (specification major version 0). Private to dyad_mcap.
#pragma once

#include <array>
#include <cstdint>

namespace dyad::mcap::format {

// 0x89 "MCAP" '0' "\r\n": begins and ends every file; '0' is the major version.
inline constexpr std::array<std::uint8_t, 8> kMagic = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

// Every record: opcode (1) + content length (uint64).
inline constexpr std::uint64_t kRecordPrefix = 1 + 8;
// Message record content before its data: channel id, sequence, log time, publish time.
inline constexpr std::uint64_t kMessageFixed = 2 + 4 + 8 + 8;
// Footer content: summary_start, summary_offset_start, summary_crc.
inline constexpr std::uint64_t kFooterContent = 8 + 8 + 4;
// Footer record + trailing magic: what an indexed reader reads first.
inline constexpr std::uint64_t kFooterAndMagic = kRecordPrefix + kFooterContent + 8;
// DataEnd record: prefix + data_section_crc.
inline constexpr std::uint64_t kDataEndRecord = kRecordPrefix + 4;

const char* OpcodeName(std::uint8_t op);

}  // namespace dyad::mcap::format
