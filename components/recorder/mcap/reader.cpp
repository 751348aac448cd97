#include "dyad/mcap/reader.hpp"

#include <zstd.h>

#include <algorithm>
#include <cstring>
#include <optional>

#include "codec.hpp"
#include "crc32.hpp"
#include "file_io.hpp"
#include "format.hpp"
#include "wire.hpp"

namespace dyad::mcap {
namespace {

using Bytes = std::span<const std::uint8_t>;

// Larger declared sizes are treated as damage rather than allocated.
constexpr std::uint64_t kMaxUncompressedChunk = std::uint64_t{4} << 30;

std::string At(const char* what, std::uint64_t offset) {
  return std::string(what) + " at offset " + std::to_string(offset);
}

// Calls fn(opcode, content) for each record in `bytes`; false if the framing is broken.
template <typename Fn>
bool ForEachRecord(Bytes bytes, Fn&& fn) {
  ByteReader r(bytes);
  while (r.remaining() > 0) {
    std::uint8_t op = 0;
    std::uint64_t len = 0;
    Bytes content;
    if (!r.Get(&op) || !r.Get(&len) || !r.Bytes(len, &content)) return false;
    if (!fn(op, content, static_cast<std::uint64_t>(content.data() - bytes.data()) - format::kRecordPrefix)) {
      return true;
    }
  }
  return true;
}

// Adds one message to the message counts and time range of *s.
void CountMessage(ChannelId channel, std::uint64_t log_time, Statistics* s) {
  if (s->message_count == 0 || log_time < s->message_start_time) s->message_start_time = log_time;
  if (s->message_count == 0 || log_time > s->message_end_time) s->message_end_time = log_time;
  ++s->message_count;
  ++s->channel_message_counts[channel];
}

// Adds the message counts and time range of `part` to *total.
void AddMessageCounts(const Statistics& part, Statistics* total) {
  if (part.message_count == 0) return;
  if (total->message_count == 0 || part.message_start_time < total->message_start_time) {
    total->message_start_time = part.message_start_time;
  }
  if (total->message_count == 0 || part.message_end_time > total->message_end_time) {
    total->message_end_time = part.message_end_time;
  }
  total->message_count += part.message_count;
  for (const auto& [channel, count] : part.channel_message_counts) total->channel_message_counts[channel] += count;
}

struct ZstdDCtxDeleter {
  void operator()(ZSTD_DCtx* ctx) const { ZSTD_freeDCtx(ctx); }
};

// The records of a summary section: what ReadSummary keeps once all of it proved sound.
struct SummaryRecords {
  std::map<SchemaId, Schema> schemas;
  std::map<ChannelId, Channel> channels;
  std::vector<ChunkInfo> chunks;
  std::vector<codec::MetadataIndexRecord> metadata_indexes;
  std::optional<Statistics> statistics;
};

// Decodes the summary section's records (starting at file offset summary_start) into *out; a
// chunk or metadata index must point inside the data section (header_end..data_end). "" or
// what is wrong with the summary.
std::string ParseSummary(Bytes summary, std::uint64_t header_end, std::uint64_t data_end, std::uint64_t summary_start,
                         SummaryRecords* out) {
  std::string problem;
  bool framed = ForEachRecord(summary, [&](std::uint8_t op, Bytes content, std::uint64_t at) {
    bool ok = true;
    switch (op) {
      case format::kSchema: {
        Schema s;
        ok = codec::DecodeSchema(content, &s);
        if (ok && s.id != 0) out->schemas.try_emplace(s.id, std::move(s));
        break;
      }
      case format::kChannel: {
        Channel c;
        ok = codec::DecodeChannel(content, &c);
        if (ok) out->channels.try_emplace(c.id, std::move(c));
        break;
      }
      case format::kChunkIndex: {
        ChunkInfo c;
        ok = codec::DecodeChunkIndex(content, &c) && c.offset >= header_end && c.length <= data_end &&
             c.offset <= data_end - c.length;
        if (ok) out->chunks.push_back(std::move(c));
        break;
      }
      case format::kMetadataIndex: {
        codec::MetadataIndexRecord m;
        ok = codec::DecodeMetadataIndex(content, &m) && m.length <= data_end && m.offset <= data_end - m.length;
        if (ok) out->metadata_indexes.push_back(std::move(m));
        break;
      }
      case format::kStatistics: {
        Statistics s;
        ok = codec::DecodeStatistics(content, &s);
        if (ok) out->statistics = std::move(s);
        break;
      }
      default:
        break;  // SummaryOffset, AttachmentIndex, newer records: not needed here.
    }
    if (!ok) problem = "bad " + std::string(format::OpcodeName(op)) + " record in the summary" +
                       " (offset " + std::to_string(summary_start + at) + ")";
    return ok;
  });
  if (!framed) return "summary records are cut or misframed";
  if (!problem.empty()) return problem;
  if (!out->statistics) return "the summary has no Statistics record";
  return "";
}

// The chunks that may hold messages of options' time range, in groups to decode together: one
// chunk in file order; in log-time order, chunks whose time ranges overlap (our writer's chunks
// do not, so groups are single chunks in practice).
std::vector<std::vector<const ChunkInfo*>> ChunkGroups(const std::vector<ChunkInfo>& chunks, const ReadOptions& options) {
  std::vector<const ChunkInfo*> selected;
  for (const ChunkInfo& c : chunks) {
    if (c.message_end_time >= options.start_time && c.message_start_time <= options.end_time) selected.push_back(&c);
  }
  std::vector<std::vector<const ChunkInfo*>> groups;
  if (options.order == ReadOptions::Order::kFile) {
    for (const ChunkInfo* c : selected) groups.push_back({c});
  } else {
    std::stable_sort(selected.begin(), selected.end(), [](const ChunkInfo* a, const ChunkInfo* b) {
      return a->message_start_time < b->message_start_time;
    });
    std::uint64_t group_end = 0;
    for (const ChunkInfo* c : selected) {
      if (groups.empty() || c->message_start_time > group_end) {
        groups.push_back({});
        group_end = 0;
      }
      groups.back().push_back(c);
      group_end = std::max(group_end, c->message_end_time);
    }
  }
  return groups;
}

}  // namespace

std::string Recovery::Describe() const {
  std::string s;
  if (!truncated) {
    s = used_summary ? "complete (summary section used)"
                     : "complete, summary not used (" + summary_problem + "); recovered by a linear scan";
  } else if (data_complete) {
    s = "cut short after the data section at byte " + std::to_string(file_size) +
        ": no messages lost (" + summary_problem + ")";
  } else {
    s = "cut short: file ends at byte " + std::to_string(file_size) + "; recovered up to byte " +
        std::to_string(valid_up_to) + " (" + stop_reason + ")";
  }
  if (!damaged_chunks.empty()) {
    s += "; " + std::to_string(damaged_chunks.size()) + " damaged chunk(s), first at offset " +
         std::to_string(damaged_chunks.begin()->first) + ": " + damaged_chunks.begin()->second;
  }
  return s;
}

class Reader::Impl {
 public:
  Status Open(const std::string& path, const ReaderOptions& options);
  Status ReadMessages(const ReadOptions& options, const std::function<bool(const MessageView&)>& visit);
  Status VerifyDataCrc();

  InputFile file_;
  Header header_;
  std::map<SchemaId, Schema> schemas_;
  std::map<ChannelId, Channel> channels_;
  std::vector<Metadata> metadata_;
  Statistics statistics_;
  std::vector<ChunkInfo> chunks_;
  Recovery recovery_;

 private:
  // "" on success, else why the summary cannot be used (nothing is kept then).
  std::string ReadSummary(std::uint64_t header_end);
  // Reads the Metadata records the summary's indexes point at into *out; "" or what is wrong.
  std::string ReadIndexedMetadata(const std::vector<codec::MetadataIndexRecord>& indexes, std::vector<Metadata>* out);
  // Reads the data section from `pos` record by record (no summary, or a file cut short):
  // what it holds up to the first damage, which recovery_ describes.
  void Scan(std::uint64_t pos);
  // Scan's reading of the record at `pos`: its opcode and content length, and its content into
  // record_ when the scan needs it. False, with recovery_.stop_reason, when the file cannot give it.
  bool ReadScannedRecord(std::uint64_t pos, std::uint8_t* op, std::uint64_t* len);
  // Scan's Chunk record at `pos` (content in record_): its schemas, channels and message counts
  // once it proves sound, else recovery_.damaged_chunks says why. `records`: scratch.
  void ScanChunk(std::uint64_t pos, std::uint64_t len, std::vector<std::uint8_t>* records);
  bool EndsWithFooter();
  // Decompresses a chunk's records into *out and checks its CRC; "" or what is wrong.
  std::string DecodeChunkRecords(const codec::ChunkRecord& chunk, std::vector<std::uint8_t>* out);
  // DataLoss "<path>: chunk at offset N: <detail>".
  Status ChunkDamaged(std::uint64_t offset, const std::string& detail) const {
    return Status::DataLoss(file_.path() + ": " + At("chunk", offset), detail);
  }
  // Reads and decodes the chunk described by `info` into *out. DataLoss names the chunk.
  Status LoadChunk(const ChunkInfo& info, std::vector<std::uint8_t>* out);
  Status ReadRecordContent(std::uint64_t offset, std::uint64_t length, std::vector<std::uint8_t>* out);
  void AddSchema(Schema schema);
  void AddChannel(Channel channel);

  std::unique_ptr<ZSTD_DCtx, ZstdDCtxDeleter> zstd_{ZSTD_createDCtx()};
  std::vector<std::uint8_t> record_;  // Scratch for one record's bytes.
  std::vector<std::vector<std::uint8_t>> chunk_buffers_;  // Decompressed chunks being read.
  std::optional<std::uint64_t> data_end_offset_;
  std::uint32_t data_crc_ = 0;
};

Status Reader::Impl::ReadRecordContent(std::uint64_t offset, std::uint64_t length,
                                       std::vector<std::uint8_t>* out) {
  out->resize(length);
  return file_.ReadAt(offset, *out);
}

void Reader::Impl::AddSchema(Schema schema) {
  if (schema.id != 0) schemas_.try_emplace(schema.id, std::move(schema));  // id 0 is invalid.
}

void Reader::Impl::AddChannel(Channel channel) { channels_.try_emplace(channel.id, std::move(channel)); }

Status Reader::Impl::Open(const std::string& path, const ReaderOptions& options) {
  if (Status s = file_.Open(path); !s.ok()) return s;
  const std::uint64_t size = file_.size();
  recovery_.file_size = size;
  recovery_.truncated = true;

  // Leading magic; a file shorter than it is a recording killed at birth if what is there matches.
  std::uint8_t magic[8] = {};
  const std::size_t have = static_cast<std::size_t>(std::min<std::uint64_t>(size, 8));
  if (Status s = file_.ReadAt(0, {magic, have}); !s.ok()) return s;
  if (std::memcmp(magic, format::kMagic.data(), have) != 0) {
    return Status::DataLoss(path, "not an MCAP file (wrong magic bytes)");
  }
  if (size < 8) {
    recovery_.stop_reason = "file ends inside the leading magic";
    recovery_.summary_problem = "no footer";
    recovery_.valid_up_to = size;
    return Status::OK();
  }

  // Header record.
  std::uint64_t header_end = 8;
  if (size - 8 < format::kRecordPrefix) {
    recovery_.stop_reason = "file ends inside the Header record";
  } else {
    std::uint8_t prefix[9];
    if (Status s = file_.ReadAt(8, prefix); !s.ok()) return s;
    std::uint64_t len = 0;
    std::memcpy(&len, prefix + 1, 8);
    if (prefix[0] != format::kHeader) return Status::DataLoss(path, "first record is not a Header");
    if (len > size - 8 - format::kRecordPrefix) {
      recovery_.stop_reason = "file ends inside the Header record";
    } else {
      if (Status s = ReadRecordContent(17, len, &record_); !s.ok()) return s;
      if (!codec::DecodeHeader(record_, &header_)) return Status::DataLoss(path, "undecodable Header record");
      header_end = 17 + len;
    }
  }
  if (header_end == 8) {
    recovery_.summary_problem = "no footer";
    recovery_.valid_up_to = 8;
    return Status::OK();
  }

  if (options.use_summary) {
    recovery_.summary_problem = ReadSummary(header_end);
    if (recovery_.summary_problem.empty()) return Status::OK();
  } else {
    recovery_.summary_problem = "summary not requested";
  }
  Scan(header_end);
  return Status::OK();
}

bool Reader::Impl::EndsWithFooter() {
  const std::uint64_t size = file_.size();
  if (size < 8 + format::kFooterAndMagic) return false;
  std::uint8_t tail[format::kFooterAndMagic];
  if (!file_.ReadAt(size - sizeof(tail), tail).ok()) return false;
  std::uint64_t len = 0;
  std::memcpy(&len, tail + 1, 8);
  return tail[0] == format::kFooter && len == format::kFooterContent &&
         std::memcmp(tail + sizeof(tail) - 8, format::kMagic.data(), 8) == 0;
}

std::string Reader::Impl::ReadSummary(std::uint64_t header_end) {
  const std::uint64_t size = file_.size();
  if (!EndsWithFooter()) return "no Footer and closing magic at the end of the file";
  const std::uint64_t footer_offset = size - format::kFooterAndMagic;
  std::uint8_t tail[format::kFooterAndMagic];
  if (!file_.ReadAt(footer_offset, tail).ok()) return "cannot read the footer";
  codec::FooterRecord footer;
  codec::DecodeFooter({tail + format::kRecordPrefix, format::kFooterContent}, &footer);
  if (footer.summary_start == 0) return "the file has no summary section";
  if (footer.summary_start < header_end + format::kDataEndRecord || footer.summary_start > footer_offset) {
    return "footer summary_start " + std::to_string(footer.summary_start) + " is out of range";
  }

  // DataEnd sits right before the summary; read both at once.
  const std::uint64_t data_end = footer.summary_start - format::kDataEndRecord;
  std::vector<std::uint8_t> bytes;
  if (!ReadRecordContent(data_end, footer_offset - data_end, &bytes).ok()) return "cannot read the summary";
  std::uint64_t data_end_len = 0;
  std::memcpy(&data_end_len, bytes.data() + 1, 8);
  if (bytes[0] != format::kDataEnd || data_end_len != 4) return "no DataEnd record before the summary";
  std::uint32_t data_crc = 0;
  std::memcpy(&data_crc, bytes.data() + format::kRecordPrefix, 4);

  const Bytes summary(bytes.data() + format::kDataEndRecord, bytes.size() - format::kDataEndRecord);
  if (footer.summary_crc != 0) {
    std::uint32_t crc = Crc32(0, summary.data(), summary.size());
    crc = Crc32(crc, tail, format::kRecordPrefix + 16);  // Footer through summary_offset_start.
    if (crc != footer.summary_crc) return "summary CRC mismatch";
  }

  SummaryRecords r;
  if (std::string problem = ParseSummary(summary, header_end, data_end, footer.summary_start, &r); !problem.empty()) {
    return problem;
  }
  std::vector<Metadata> metadata;
  if (std::string problem = ReadIndexedMetadata(r.metadata_indexes, &metadata); !problem.empty()) return problem;

  std::sort(r.chunks.begin(), r.chunks.end(), [](const ChunkInfo& a, const ChunkInfo& b) { return a.offset < b.offset; });
  schemas_ = std::move(r.schemas);
  channels_ = std::move(r.channels);
  chunks_ = std::move(r.chunks);
  metadata_ = std::move(metadata);
  statistics_ = std::move(*r.statistics);
  data_end_offset_ = data_end;
  data_crc_ = data_crc;
  recovery_.used_summary = true;
  recovery_.truncated = false;
  recovery_.data_complete = true;
  recovery_.valid_up_to = size;
  return "";
}

std::string Reader::Impl::ReadIndexedMetadata(const std::vector<codec::MetadataIndexRecord>& indexes,
                                              std::vector<Metadata>* out) {
  for (const auto& index : indexes) {
    if (index.length < format::kRecordPrefix ||
        !ReadRecordContent(index.offset, index.length, &record_).ok() || record_[0] != format::kMetadata) {
      return "MetadataIndex for \"" + index.name + "\" does not point at a Metadata record";
    }
    Metadata m;
    if (!codec::DecodeMetadata(Bytes(record_).subspan(format::kRecordPrefix), &m)) {
      return "undecodable Metadata record at offset " + std::to_string(index.offset);
    }
    out->push_back(std::move(m));
  }
  return "";
}

std::string Reader::Impl::DecodeChunkRecords(const codec::ChunkRecord& chunk, std::vector<std::uint8_t>* out) {
  // The declared size is checked against what the stored bytes can hold before it is allocated:
  // a damaged size field must not cost gigabytes.
  auto declared = [&] { return "declared uncompressed size " + std::to_string(chunk.uncompressed_size); };
  if (chunk.compression.empty()) {
    if (chunk.records.size() != chunk.uncompressed_size) {
      return declared() + " differs from the " + std::to_string(chunk.records.size()) + " bytes stored";
    }
    out->assign(chunk.records.begin(), chunk.records.end());
  } else if (chunk.compression == "zstd") {
    const unsigned long long frame_size = ZSTD_getFrameContentSize(chunk.records.data(), chunk.records.size());
    if (frame_size == ZSTD_CONTENTSIZE_ERROR) return "zstd: not a zstd frame";
    if (frame_size != ZSTD_CONTENTSIZE_UNKNOWN && frame_size != chunk.uncompressed_size) {
      return declared() + " differs from the zstd frame's " + std::to_string(frame_size) + " bytes";
    }
    if (chunk.uncompressed_size > kMaxUncompressedChunk) return declared() + " is implausible";
    // A zstd block holds at most 128 KiB and takes at least 3 bytes: what the stored bytes can
    // really expand to bounds the allocation (a frame header may claim any size, or none).
    const std::uint64_t expandable = (chunk.records.size() / 3 + 1) * (std::uint64_t{128} << 10);
    if (chunk.uncompressed_size > expandable) {
      return declared() + " is more than " + std::to_string(chunk.records.size()) + " zstd bytes can hold";
    }
    out->resize(chunk.uncompressed_size);
    std::size_t n = ZSTD_decompressDCtx(zstd_.get(), out->data(), out->size(), chunk.records.data(),
                                        chunk.records.size());
    if (ZSTD_isError(n)) return std::string("zstd: ") + ZSTD_getErrorName(n);
    if (n != chunk.uncompressed_size) return "decompressed to a different size than declared";
  } else {
    return "unsupported compression \"" + chunk.compression + "\"";
  }
  if (chunk.uncompressed_crc != 0) {
    const std::uint32_t crc = Crc32(0, out->data(), out->size());
    if (crc != chunk.uncompressed_crc) {
      char text[80];
      std::snprintf(text, sizeof(text), "CRC mismatch (stored 0x%08x, computed 0x%08x)", chunk.uncompressed_crc, crc);
      return text;
    }
  }
  return "";
}

bool Reader::Impl::ReadScannedRecord(std::uint64_t pos, std::uint8_t* op_out, std::uint64_t* len_out) {
  const std::uint64_t size = file_.size();
  if (size - pos < format::kRecordPrefix) {
    recovery_.stop_reason = "file ends inside a record prefix at offset " + std::to_string(pos);
    return false;
  }
  std::uint8_t prefix[9];
  if (!file_.ReadAt(pos, prefix).ok()) {
    recovery_.stop_reason = At("read error", pos);
    return false;
  }
  const std::uint8_t op = *op_out = prefix[0];
  std::uint64_t& len = *len_out;
  std::memcpy(&len, prefix + 1, 8);
  if (len > size - pos - format::kRecordPrefix) {
    recovery_.stop_reason = std::string(format::OpcodeName(op)) + " record at offset " + std::to_string(pos) +
                            " needs " + std::to_string(format::kRecordPrefix + len) +
                            " bytes, file ends at " + std::to_string(size);
    return false;
  }
  // Index records are not needed for a scan: skip their bytes without reading them.
  const bool wanted = op == format::kSchema || op == format::kChannel || op == format::kChunk ||
                      op == format::kMetadata || op == format::kDataEnd;
  if (wanted && !ReadRecordContent(pos + format::kRecordPrefix, len, &record_).ok()) {
    recovery_.stop_reason = At("read error", pos);
    return false;
  }
  return true;
}

void Reader::Impl::ScanChunk(std::uint64_t pos, std::uint64_t len, std::vector<std::uint8_t>* records_buffer) {
  std::vector<std::uint8_t>& records = *records_buffer;
  codec::ChunkRecord chunk;
  std::string damage = codec::DecodeChunk(record_, &chunk) ? DecodeChunkRecords(chunk, &records)
                                                             : "undecodable Chunk record";
  if (damage.empty()) {
    // Schemas and channels may live inside chunks (other writers put them there). The
    // messages count only once the whole chunk has proved well framed.
    Statistics in_chunk;
    bool framed = ForEachRecord(records, [&](std::uint8_t inner, Bytes content, std::uint64_t) {
      if (inner == format::kSchema) {
        Schema s;
        if (codec::DecodeSchema(content, &s)) AddSchema(std::move(s));
      } else if (inner == format::kChannel) {
        Channel c;
        if (codec::DecodeChannel(content, &c)) AddChannel(std::move(c));
      } else if (inner == format::kMessage) {
        codec::MessageRecord m;
        if (!codec::DecodeMessage(content, &m)) return false;
        CountMessage(m.channel_id, m.log_time, &in_chunk);
      }
      return true;
    });
    if (framed) {
      AddMessageCounts(in_chunk, &statistics_);
    } else {
      damage = "records inside the chunk are misframed";
    }
  }
  if (damage.empty()) {
    ChunkInfo info;
    info.offset = pos;
    info.length = format::kRecordPrefix + len;
    info.message_start_time = chunk.message_start_time;
    info.message_end_time = chunk.message_end_time;
    info.compression = chunk.compression;
    info.compressed_size = chunk.records.size();
    info.uncompressed_size = chunk.uncompressed_size;
    chunks_.push_back(std::move(info));
  } else {
    recovery_.damaged_chunks[pos] = damage;
  }
}

void Reader::Impl::Scan(std::uint64_t pos) {
  const std::uint64_t size = file_.size();
  Statistics& stats = statistics_;
  stats = Statistics();
  std::vector<std::uint8_t> records;
  recovery_.valid_up_to = pos;
  recovery_.stop_reason = "file ends after the record at offset " + std::to_string(pos);
  bool done = false;
  while (!done) {
    if (pos == size) break;
    std::uint8_t op = 0;
    std::uint64_t len = 0;
    if (!ReadScannedRecord(pos, &op, &len)) break;
    bool ok = true;
    switch (op) {
      case format::kSchema: {
        Schema s;
        ok = codec::DecodeSchema(record_, &s);
        if (ok) AddSchema(std::move(s));
        break;
      }
      case format::kChannel: {
        Channel c;
        ok = codec::DecodeChannel(record_, &c);
        if (ok) AddChannel(std::move(c));
        break;
      }
      case format::kMessage:
        ++recovery_.loose_messages;
        break;
      case format::kMetadata: {
        Metadata m;
        ok = codec::DecodeMetadata(record_, &m);
        if (ok) metadata_.push_back(std::move(m));
        break;
      }
      case format::kAttachment:
        ++stats.attachment_count;
        break;
      case format::kChunk:
        ScanChunk(pos, len, &records);
        break;
      case format::kDataEnd:
        recovery_.data_complete = true;
        if (codec::DecodeDataEnd(record_, &data_crc_)) data_end_offset_ = pos;
        recovery_.stop_reason = "reached DataEnd at offset " + std::to_string(pos);
        done = true;  // The summary follows; everything it repeats is known by now.
        break;
      case format::kFooter:
        recovery_.data_complete = true;
        recovery_.stop_reason = "reached Footer at offset " + std::to_string(pos);
        done = true;
        break;
      default:
        break;  // MessageIndex, index records, records newer than this reader.
    }
    if (!ok) {
      recovery_.stop_reason = "undecodable " + std::string(format::OpcodeName(op)) + " record at offset " +
                              std::to_string(pos);
      break;
    }
    pos += format::kRecordPrefix + len;
    recovery_.valid_up_to = pos;
  }
  recovery_.truncated = !EndsWithFooter();
  stats.schema_count = static_cast<std::uint16_t>(schemas_.size());
  stats.channel_count = static_cast<std::uint32_t>(channels_.size());
  stats.metadata_count = static_cast<std::uint32_t>(metadata_.size());
  stats.chunk_count = static_cast<std::uint32_t>(chunks_.size());
}

Status Reader::Impl::LoadChunk(const ChunkInfo& info, std::vector<std::uint8_t>* out) {
  if (info.length < format::kRecordPrefix) return ChunkDamaged(info.offset, "too short");
  if (Status s = ReadRecordContent(info.offset, info.length, &record_); !s.ok()) return s;
  std::uint64_t len = 0;
  std::memcpy(&len, record_.data() + 1, 8);
  codec::ChunkRecord chunk;
  if (record_[0] != format::kChunk || len != info.length - format::kRecordPrefix ||
      !codec::DecodeChunk(Bytes(record_).subspan(format::kRecordPrefix), &chunk)) {
    return ChunkDamaged(info.offset, "no valid Chunk record there");
  }
  if (std::string damage = DecodeChunkRecords(chunk, out); !damage.empty()) return ChunkDamaged(info.offset, damage);
  return Status::OK();
}

Status Reader::Impl::ReadMessages(const ReadOptions& options,
                                  const std::function<bool(const MessageView&)>& visit) {
  if (!recovery_.damaged_chunks.empty()) {
    if (!options.skip_damaged) {
      const auto& [offset, why] = *recovery_.damaged_chunks.begin();
      return ChunkDamaged(offset, why);
    }
    if (options.skipped_chunks) *options.skipped_chunks += recovery_.damaged_chunks.size();
  }

  std::vector<bool> channel_chosen(65536, options.topics.empty());
  for (const auto& [id, channel] : channels_) {
    if (options.topics.count(channel.topic)) channel_chosen[id] = true;
  }

  struct Pending {
    std::uint64_t log_time;
    codec::MessageRecord record;
  };
  std::vector<Pending> pending;
  Status status;
  // Appends the chosen messages of a decoded chunk to `pending`.
  auto collect = [&](const std::vector<std::uint8_t>& records, const ChunkInfo& info) {
    bool framed = ForEachRecord(records, [&](std::uint8_t op, Bytes content, std::uint64_t) {
      if (op != format::kMessage) return true;
      codec::MessageRecord m;
      if (!codec::DecodeMessage(content, &m)) return false;
      if (!channel_chosen[m.channel_id] || m.log_time < options.start_time || m.log_time > options.end_time) {
        return true;
      }
      if (!channels_.count(m.channel_id)) {
        status = ChunkDamaged(info.offset, "message on unknown channel " + std::to_string(m.channel_id));
        return false;
      }
      pending.push_back({m.log_time, m});
      return true;
    });
    if (!framed && status.ok()) {
      status = ChunkDamaged(info.offset, "misframed records");
    }
  };
  // Delivers `pending`; false when the visitor asked to stop.
  auto deliver = [&]() {
    for (const Pending& p : pending) {
      MessageView view{&channels_.at(p.record.channel_id), p.record.sequence, p.record.log_time,
                       p.record.publish_time, p.record.data};
      if (!visit(view)) return false;
    }
    pending.clear();
    return true;
  };

  std::vector<std::vector<const ChunkInfo*>> groups = ChunkGroups(chunks_, options);
  for (auto& group : groups) {
    // File order within a group so that equal log times keep their writing order.
    std::sort(group.begin(), group.end(), [](const ChunkInfo* a, const ChunkInfo* b) { return a->offset < b->offset; });
    if (chunk_buffers_.size() < group.size()) chunk_buffers_.resize(group.size());
    for (std::size_t i = 0; i < group.size(); ++i) {
      if (Status s = LoadChunk(*group[i], &chunk_buffers_[i]); !s.ok()) {
        if (!options.skip_damaged) return s;
        if (options.skipped_chunks) ++*options.skipped_chunks;
        chunk_buffers_[i].clear();
        continue;
      }
      collect(chunk_buffers_[i], *group[i]);
      if (!status.ok()) return status;
    }
    auto earlier = [](const Pending& a, const Pending& b) { return a.log_time < b.log_time; };
    if (options.order == ReadOptions::Order::kLogTime && !std::is_sorted(pending.begin(), pending.end(), earlier)) {
      std::stable_sort(pending.begin(), pending.end(), earlier);
    }
    if (!deliver()) return Status::OK();
  }
  return Status::OK();
}

Status Reader::Impl::VerifyDataCrc() {
  if (!data_end_offset_ || data_crc_ == 0) {
    return Status::FailedPrecondition(file_.path(), "no DataEnd record with a data-section CRC");
  }
  std::vector<std::uint8_t> block(1 << 20);
  std::uint32_t crc = 0;
  for (std::uint64_t pos = 0; pos < *data_end_offset_;) {
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(block.size(), *data_end_offset_ - pos));
    if (Status s = file_.ReadAt(pos, {block.data(), n}); !s.ok()) return s;
    crc = Crc32(crc, block.data(), n);
    pos += n;
  }
  if (crc != data_crc_) {
    char text[96];
    std::snprintf(text, sizeof(text), "data-section CRC mismatch (stored 0x%08x, computed 0x%08x)", data_crc_, crc);
    return Status::DataLoss(file_.path(), text);
  }
  return Status::OK();
}

Reader::Reader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Reader::Reader(Reader&&) noexcept = default;
Reader& Reader::operator=(Reader&&) noexcept = default;
Reader::~Reader() = default;

StatusOr<Reader> Reader::Open(const std::string& path, const ReaderOptions& options) {
  auto impl = std::make_unique<Impl>();
  if (Status s = impl->Open(path, options); !s.ok()) return s;
  return Reader(std::move(impl));
}

const std::string& Reader::path() const { return impl_->file_.path(); }
const Header& Reader::header() const { return impl_->header_; }
const std::map<SchemaId, Schema>& Reader::schemas() const { return impl_->schemas_; }
const std::map<ChannelId, Channel>& Reader::channels() const { return impl_->channels_; }
const std::vector<Metadata>& Reader::metadata() const { return impl_->metadata_; }
const Statistics& Reader::statistics() const { return impl_->statistics_; }
const std::vector<ChunkInfo>& Reader::chunks() const { return impl_->chunks_; }
const Recovery& Reader::recovery() const { return impl_->recovery_; }

Status Reader::ReadMessages(const ReadOptions& options,
                            const std::function<bool(const MessageView&)>& visit) const {
  return impl_->ReadMessages(options, visit);
}

Status Reader::VerifyDataCrc() const { return impl_->VerifyDataCrc(); }

}  // namespace dyad::mcap
