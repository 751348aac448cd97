// Encoding and decoding of MCAP record contents. Private to dyad_mcap.
//
// Encode* append a whole record (opcode, length, content) to a ByteBuffer.
// Decode* parse a record's content (without opcode and length) and return false when it is too
// short or inconsistent; fields added by newer writers after the known ones are ignored, as the
// specification asks.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "dyad/mcap/records.hpp"
#include "wire.hpp"

namespace dyad::mcap::codec {

using Bytes = std::span<const std::uint8_t>;

struct ChunkIndexRecord {
  ChunkInfo info;
  // (channel id, file offset of its MessageIndex record after the chunk), in writing order.
  std::vector<std::pair<ChannelId, std::uint64_t>> message_index_offsets;
  std::uint64_t message_index_length = 0;
};

struct ChunkRecord {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;
  std::string compression;
  Bytes records;  // Compressed as `compression` says.
};

struct MessageRecord {
  ChannelId channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;
  std::uint64_t publish_time = 0;
  Bytes data;
};

struct MetadataIndexRecord {
  std::uint64_t offset = 0;
  std::uint64_t length = 0;
  std::string name;
};

struct SummaryOffsetRecord {
  std::uint8_t group_opcode = 0;
  std::uint64_t group_start = 0;
  std::uint64_t group_length = 0;
};

struct FooterRecord {
  std::uint64_t summary_start = 0;
  std::uint64_t summary_offset_start = 0;
  std::uint32_t summary_crc = 0;
};

void EncodeHeader(const Header& header, ByteBuffer* out);
void EncodeSchema(const Schema& schema, ByteBuffer* out);
void EncodeChannel(const Channel& channel, ByteBuffer* out);
void EncodeMetadata(const Metadata& metadata, ByteBuffer* out);
void EncodeStatistics(const Statistics& statistics, ByteBuffer* out);
void EncodeChunkIndex(const ChunkIndexRecord& index, ByteBuffer* out);
void EncodeMetadataIndex(const MetadataIndexRecord& index, ByteBuffer* out);
void EncodeSummaryOffset(const SummaryOffsetRecord& offset, ByteBuffer* out);
void EncodeDataEnd(std::uint32_t data_section_crc, ByteBuffer* out);
// Appends the footer except its CRC field, which covers the bytes before it: the caller computes
// the CRC over the summary and this prefix, then appends it with PutU32 and the magic.
void EncodeFooterPrefix(std::uint64_t summary_start, std::uint64_t summary_offset_start, ByteBuffer* out);

bool DecodeHeader(Bytes content, Header* out);
bool DecodeSchema(Bytes content, Schema* out);
bool DecodeChannel(Bytes content, Channel* out);
bool DecodeMessage(Bytes content, MessageRecord* out);
bool DecodeChunk(Bytes content, ChunkRecord* out);
bool DecodeChunkIndex(Bytes content, ChunkInfo* out);
bool DecodeMetadata(Bytes content, Metadata* out);
bool DecodeMetadataIndex(Bytes content, MetadataIndexRecord* out);
bool DecodeStatistics(Bytes content, Statistics* out);
bool DecodeDataEnd(Bytes content, std::uint32_t* data_section_crc);
bool DecodeFooter(Bytes content, FooterRecord* out);

}  // namespace dyad::mcap::codec
