#include "codec.hpp"

#include "format.hpp"

namespace dyad::mcap::codec {

void EncodeHeader(const Header& header, ByteBuffer* out) {
  std::size_t len = out->BeginRecord(format::kHeader);
  out->PutString(header.profile);
  out->PutString(header.library);
  out->EndRecord(len);
}

void EncodeSchema(const Schema& schema, ByteBuffer* out) {
  std::size_t len = out->BeginRecord(format::kSchema);
  out->PutU16(schema.id);
  out->PutString(schema.name);
  out->PutString(schema.encoding);
  out->PutString(schema.data);  // uint32 length-prefixed bytes: same layout as a string.
  out->EndRecord(len);
}

void EncodeChannel(const Channel& channel, ByteBuffer* out) {
  std::size_t len = out->BeginRecord(format::kChannel);
  out->PutU16(channel.id);
  out->PutU16(channel.schema_id);
  out->PutString(channel.topic);
  out->PutString(channel.message_encoding);
  out->PutStringMap(channel.metadata);
  out->EndRecord(len);
}

void EncodeMetadata(const Metadata& metadata, ByteBuffer* out) {
  std::size_t len = out->BeginRecord(format::kMetadata);
  out->PutString(metadata.name);
  out->PutStringMap(metadata.entries);
  out->EndRecord(len);
}

void EncodeStatistics(const Statistics& s, ByteBuffer* out) {
  std::size_t len = out->BeginRecord(format::kStatistics);
  out->PutU64(s.message_count);
  out->PutU16(s.schema_count);
  out->PutU32(s.channel_count);
  out->PutU32(s.attachment_count);
  out->PutU32(s.metadata_count);
  out->PutU32(s.chunk_count);
  out->PutU64(s.message_start_time);
  out->PutU64(s.message_end_time);
  out->PutU32(static_cast<std::uint32_t>(s.channel_message_counts.size() * (2 + 8)));
  for (const auto& [id, count] : s.channel_message_counts) {
    out->PutU16(id);
    out->PutU64(count);
  }
  out->EndRecord(len);
}

void EncodeChunkIndex(const ChunkIndexRecord& index, ByteBuffer* out) {
  const ChunkInfo& c = index.info;
  std::size_t len = out->BeginRecord(format::kChunkIndex);
  out->PutU64(c.message_start_time);
  out->PutU64(c.message_end_time);
  out->PutU64(c.offset);
  out->PutU64(c.length);
  out->PutU32(static_cast<std::uint32_t>(index.message_index_offsets.size() * (2 + 8)));
  for (const auto& [id, offset] : index.message_index_offsets) {
    out->PutU16(id);
    out->PutU64(offset);
  }
  out->PutU64(index.message_index_length);
  out->PutString(c.compression);
  out->PutU64(c.compressed_size);
  out->PutU64(c.uncompressed_size);
  out->EndRecord(len);
}

void EncodeMetadataIndex(const MetadataIndexRecord& index, ByteBuffer* out) {
  std::size_t len = out->BeginRecord(format::kMetadataIndex);
  out->PutU64(index.offset);
  out->PutU64(index.length);
  out->PutString(index.name);
  out->EndRecord(len);
}

void EncodeSummaryOffset(const SummaryOffsetRecord& offset, ByteBuffer* out) {
  std::size_t len = out->BeginRecord(format::kSummaryOffset);
  out->PutU8(offset.group_opcode);
  out->PutU64(offset.group_start);
  out->PutU64(offset.group_length);
  out->EndRecord(len);
}

void EncodeDataEnd(std::uint32_t data_section_crc, ByteBuffer* out) {
  std::size_t len = out->BeginRecord(format::kDataEnd);
  out->PutU32(data_section_crc);
  out->EndRecord(len);
}

void EncodeFooterPrefix(std::uint64_t summary_start, std::uint64_t summary_offset_start, ByteBuffer* out) {
  out->PutU8(format::kFooter);
  out->PutU64(format::kFooterContent);
  out->PutU64(summary_start);
  out->PutU64(summary_offset_start);
}

bool DecodeHeader(Bytes content, Header* out) {
  ByteReader r(content);
  return r.String(&out->profile) && r.String(&out->library);
}

bool DecodeSchema(Bytes content, Schema* out) {
  ByteReader r(content);
  return r.Get(&out->id) && r.String(&out->name) && r.String(&out->encoding) && r.String(&out->data);
}

bool DecodeChannel(Bytes content, Channel* out) {
  ByteReader r(content);
  return r.Get(&out->id) && r.Get(&out->schema_id) && r.String(&out->topic) &&
         r.String(&out->message_encoding) && r.StringMap(&out->metadata);
}

bool DecodeMessage(Bytes content, MessageRecord* out) {
  ByteReader r(content);
  if (!r.Get(&out->channel_id) || !r.Get(&out->sequence) || !r.Get(&out->log_time) ||
      !r.Get(&out->publish_time)) {
    return false;
  }
  // The data runs to the end of the record: Message records cannot be extended.
  return r.Bytes(r.remaining(), &out->data);
}

bool DecodeChunk(Bytes content, ChunkRecord* out) {
  ByteReader r(content);
  std::uint64_t records_size = 0;
  return r.Get(&out->message_start_time) && r.Get(&out->message_end_time) &&
         r.Get(&out->uncompressed_size) && r.Get(&out->uncompressed_crc) &&
         r.String(&out->compression) && r.Get(&records_size) && r.Bytes(records_size, &out->records);
}

bool DecodeChunkIndex(Bytes content, ChunkInfo* out) {
  ByteReader r(content);
  std::uint32_t offsets_size = 0;
  std::uint64_t message_index_length = 0;
  return r.Get(&out->message_start_time) && r.Get(&out->message_end_time) && r.Get(&out->offset) &&
         r.Get(&out->length) && r.Get(&offsets_size) && r.Skip(offsets_size) &&
         r.Get(&message_index_length) && r.String(&out->compression) &&
         r.Get(&out->compressed_size) && r.Get(&out->uncompressed_size);
}

bool DecodeMetadata(Bytes content, Metadata* out) {
  ByteReader r(content);
  return r.String(&out->name) && r.StringMap(&out->entries);
}

bool DecodeMetadataIndex(Bytes content, MetadataIndexRecord* out) {
  ByteReader r(content);
  return r.Get(&out->offset) && r.Get(&out->length) && r.String(&out->name);
}

bool DecodeStatistics(Bytes content, Statistics* out) {
  ByteReader r(content);
  std::uint32_t counts_size = 0;
  Bytes counts;
  if (!r.Get(&out->message_count) || !r.Get(&out->schema_count) || !r.Get(&out->channel_count) ||
      !r.Get(&out->attachment_count) || !r.Get(&out->metadata_count) || !r.Get(&out->chunk_count) ||
      !r.Get(&out->message_start_time) || !r.Get(&out->message_end_time) || !r.Get(&counts_size) ||
      !r.Bytes(counts_size, &counts)) {
    return false;
  }
  ByteReader c(counts);
  out->channel_message_counts.clear();
  while (c.remaining() > 0) {
    ChannelId id = 0;
    std::uint64_t count = 0;
    if (!c.Get(&id) || !c.Get(&count)) return false;
    out->channel_message_counts[id] = count;
  }
  return true;
}

bool DecodeDataEnd(Bytes content, std::uint32_t* data_section_crc) {
  ByteReader r(content);
  return r.Get(data_section_crc);
}

bool DecodeFooter(Bytes content, FooterRecord* out) {
  ByteReader r(content);
  return r.Get(&out->summary_start) && r.Get(&out->summary_offset_start) && r.Get(&out->summary_crc);
}

}  // namespace dyad::mcap::codec
