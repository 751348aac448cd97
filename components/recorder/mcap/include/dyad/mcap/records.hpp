// The MCAP records that dyad_mcap exposes, as plain values.
//
// Field meanings follow the MCAP specification (major version 0). Times are uint64 nanoseconds
// since an epoch the recording chooses (dyad uses the Unix epoch). Ids are the file's own: schema
// id 0 means "no schema"; channel ids start at 0 or 1 depending on the writer (ours start at 1).
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <string>

namespace dyad::mcap {

using SchemaId = std::uint16_t;
using ChannelId = std::uint16_t;

// Header record: written once after the leading magic.
struct Header {
  std::string profile;  // e.g. "" or "ros2"; "" means no well-known profile.
  std::string library;  // Free-form writer identification.
};

struct Schema {
  SchemaId id = 0;
  std::string name;      // e.g. "dyad::msg::Pose2" (IDL type name).
  std::string encoding;  // e.g. "omgidl"; "" means no schema.
  std::string data;      // Schema text or bytes, per `encoding`.
};

struct Channel {
  ChannelId id = 0;
  SchemaId schema_id = 0;
  std::string topic;
  std::string message_encoding;  // e.g. "cdr".
  std::map<std::string, std::string> metadata;
};

// Metadata record: named key/value strings (dyad stores the graph YAML here).
struct Metadata {
  std::string name;
  std::map<std::string, std::string> entries;
};

// Statistics record, or the same numbers recomputed by a linear scan.
struct Statistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t attachment_count = 0;
  std::uint32_t metadata_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time = 0;  // 0 when there are no messages.
  std::uint64_t message_end_time = 0;
  std::map<ChannelId, std::uint64_t> channel_message_counts;
};

// Where a chunk is and what it holds (from a ChunkIndex record or a scan).
struct ChunkInfo {
  std::uint64_t offset = 0;  // Of the Chunk record's opcode, from the start of the file.
  std::uint64_t length = 0;  // Whole record: opcode + length prefix + content.
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::string compression;  // "zstd" or "" (none); others are reported as unsupported on read.
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
};

// One message as seen while reading. `data` points into the reader's buffers and is valid only
// during the callback that receives it; copy it to keep it.
struct MessageView {
  const Channel* channel = nullptr;  // Never null: messages on unknown channels are reported as errors.
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;
  std::uint64_t publish_time = 0;
  std::span<const std::uint8_t> data;
};

}  // namespace dyad::mcap
