#include "dyad/mcap/writer.hpp"

#include <zstd.h>

#include <utility>
#include <vector>

#include "codec.hpp"
#include "crc32.hpp"
#include "file_io.hpp"
#include "format.hpp"
#include "wire.hpp"

namespace dyad::mcap {
namespace {

struct ZstdCCtxDeleter {
  void operator()(ZSTD_CCtx* ctx) const { ZSTD_freeCCtx(ctx); }
};

// Messages of one channel in the chunk being filled: (log time, offset in the uncompressed chunk).
// Cleared, not freed, at each chunk, so steady-state writes do not allocate.
struct ChannelState {
  std::vector<std::pair<std::uint64_t, std::uint64_t>> index;
  std::uint64_t message_count = 0;
};

iovec Iov(const ByteBuffer& b) { return {const_cast<std::uint8_t*>(b.data()), b.size()}; }

}  // namespace

Status WriterOptions::Validate() const {
  if (chunk_size < 1024 || chunk_size > (std::uint64_t{1} << 30)) {
    return Status::InvalidArgument("WriterOptions",
                                   "chunk_size = " + std::to_string(chunk_size) +
                                       ": must be between 1024 and 1073741824 bytes");
  }
  if (compression == Compression::kZstd && (zstd_level < 1 || zstd_level > 19)) {
    return Status::InvalidArgument("WriterOptions",
                                   "zstd_level = " + std::to_string(zstd_level) + ": must be 1..19");
  }
  return Status::OK();
}

class Writer::Impl {
 public:
  Status Open(const std::string& path, const WriterOptions& options);
  StatusOr<SchemaId> AddSchema(std::string_view name, std::string_view encoding, std::string_view data);
  StatusOr<ChannelId> AddChannel(std::string_view topic, std::string_view message_encoding,
                                 SchemaId schema_id, const std::map<std::string, std::string>& metadata);
  Status Write(ChannelId channel_id, std::uint32_t sequence, std::uint64_t log_time,
               std::uint64_t publish_time, std::span<const std::uint8_t> data);
  Status AddMetadata(std::string_view name, const std::map<std::string, std::string>& entries);
  Status Flush();
  Status Close();

  std::uint64_t bytes_written() const { return pos_; }
  std::uint64_t message_count() const { return message_count_; }
  const std::string& path() const { return file_.path(); }

 private:
  // Ok, or the error that stopped the writer, or FailedPrecondition after Close.
  Status Usable(const char* call) const;
  // Writes buffers to the file, keeping the running data-section CRC and the position.
  Status Emit(std::span<const iovec> buffers, bool in_data_section);
  Status CloseChunk();
  Status Fail(Status status) {
    failed_ = status;
    return status;
  }

  OutputFile file_;
  WriterOptions options_;
  Status failed_;
  bool closed_ = false;
  Status close_status_;

  std::uint64_t pos_ = 0;          // Bytes written to the file.
  std::uint32_t data_crc_ = 0;     // CRC32 of everything written before DataEnd.

  std::vector<Schema> schemas_;    // schemas_[id - 1]
  std::vector<Channel> channels_;  // channels_[id - 1]
  std::vector<ChannelState> states_;  // states_[id - 1]

  // The chunk being filled.
  ByteBuffer chunk_;
  std::uint64_t chunk_start_time_ = 0;
  std::uint64_t chunk_end_time_ = 0;
  std::vector<ChannelId> chunk_channels_;  // Channels with messages in it, in first-use order.

  ByteBuffer compressed_;
  ByteBuffer chunk_prefix_;
  ByteBuffer message_indexes_;
  ByteBuffer scratch_;
  std::unique_ptr<ZSTD_CCtx, ZstdCCtxDeleter> zstd_;

  std::vector<codec::ChunkIndexRecord> chunk_indexes_;
  std::vector<codec::MetadataIndexRecord> metadata_indexes_;
  std::uint64_t message_count_ = 0;
  std::uint64_t message_start_time_ = 0;
  std::uint64_t message_end_time_ = 0;
};

Status Writer::Impl::Open(const std::string& path, const WriterOptions& options) {
  if (Status s = options.Validate(); !s.ok()) return Status::InvalidArgument(path, s.message());
  options_ = options;
  if (Status s = file_.Open(path, options.replace_existing); !s.ok()) return s;
  if (options_.compression == Compression::kZstd) {
    zstd_.reset(ZSTD_createCCtx());
    if (!zstd_) return Status::IOError(path, "cannot create a zstd compression context");
    ZSTD_CCtx_setParameter(zstd_.get(), ZSTD_c_compressionLevel, options_.zstd_level);
    ZSTD_CCtx_setParameter(zstd_.get(), ZSTD_c_checksumFlag, 0);  // The chunk CRC already covers it.
  }
  // Headroom so a chunk that crosses the threshold with one message does not reallocate.
  chunk_.Reserve(options_.chunk_size + 64 * 1024);
  scratch_.PutBytes(format::kMagic.data(), format::kMagic.size());
  codec::EncodeHeader({options_.profile, options_.library}, &scratch_);
  iovec iov = Iov(scratch_);
  return Emit({&iov, 1}, true);
}

Status Writer::Impl::Usable(const char* call) const {
  if (!failed_.ok()) return failed_;
  if (closed_) return Status::FailedPrecondition(path(), std::string(call) + " after Close");
  return Status::OK();
}

Status Writer::Impl::Emit(std::span<const iovec> buffers, bool in_data_section) {
  if (Status s = file_.Write(buffers); !s.ok()) return Fail(s);
  for (const iovec& b : buffers) {
    if (in_data_section) data_crc_ = Crc32(data_crc_, b.iov_base, b.iov_len);
    pos_ += b.iov_len;
  }
  return Status::OK();
}

StatusOr<SchemaId> Writer::Impl::AddSchema(std::string_view name, std::string_view encoding,
                                           std::string_view data) {
  if (Status s = Usable("AddSchema"); !s.ok()) return s;
  for (const Schema& schema : schemas_) {
    if (schema.name == name && schema.encoding == encoding && schema.data == data) return schema.id;
  }
  if (schemas_.size() >= 0xFFFF) return Status::InvalidArgument(path(), "AddSchema: more than 65535 schemas");
  Schema schema{static_cast<SchemaId>(schemas_.size() + 1), std::string(name), std::string(encoding),
                std::string(data)};
  scratch_.Clear();
  codec::EncodeSchema(schema, &scratch_);
  iovec iov = Iov(scratch_);
  if (Status s = Emit({&iov, 1}, true); !s.ok()) return s;
  schemas_.push_back(std::move(schema));
  return schemas_.back().id;
}

StatusOr<ChannelId> Writer::Impl::AddChannel(std::string_view topic, std::string_view message_encoding,
                                             SchemaId schema_id,
                                             const std::map<std::string, std::string>& metadata) {
  if (Status s = Usable("AddChannel"); !s.ok()) return s;
  if (schema_id > schemas_.size()) {
    return Status::InvalidArgument(path(), "AddChannel(\"" + std::string(topic) +
                                               "\"): unknown schema id " + std::to_string(schema_id));
  }
  if (channels_.size() >= 0xFFFF) return Status::InvalidArgument(path(), "AddChannel: more than 65535 channels");
  Channel channel{static_cast<ChannelId>(channels_.size() + 1), schema_id, std::string(topic),
                  std::string(message_encoding), metadata};
  scratch_.Clear();
  codec::EncodeChannel(channel, &scratch_);
  iovec iov = Iov(scratch_);
  if (Status s = Emit({&iov, 1}, true); !s.ok()) return s;
  channels_.push_back(std::move(channel));
  states_.emplace_back();
  chunk_channels_.reserve(channels_.size());
  return channels_.back().id;
}

Status Writer::Impl::Write(ChannelId channel_id, std::uint32_t sequence, std::uint64_t log_time,
                           std::uint64_t publish_time, std::span<const std::uint8_t> data) {
  if (!failed_.ok() || closed_) return Usable("Write");
  if (channel_id == 0 || channel_id > channels_.size()) {
    return Status::InvalidArgument(path(), "Write: unknown channel id " + std::to_string(channel_id));
  }
  const std::uint64_t offset = chunk_.size();
  const std::uint64_t content = format::kMessageFixed + data.size();
  std::uint8_t* p = chunk_.Extend(format::kRecordPrefix + content);
  *p = format::kMessage;
  std::memcpy(p + 1, &content, 8);
  std::memcpy(p + 9, &channel_id, 2);
  std::memcpy(p + 11, &sequence, 4);
  std::memcpy(p + 15, &log_time, 8);
  std::memcpy(p + 23, &publish_time, 8);
  if (!data.empty()) std::memcpy(p + 31, data.data(), data.size());

  ChannelState& state = states_[channel_id - 1];
  if (state.index.empty()) chunk_channels_.push_back(channel_id);
  state.index.emplace_back(log_time, offset);
  ++state.message_count;
  if (offset == 0 || log_time < chunk_start_time_) chunk_start_time_ = log_time;
  if (offset == 0 || log_time > chunk_end_time_) chunk_end_time_ = log_time;
  if (message_count_ == 0 || log_time < message_start_time_) message_start_time_ = log_time;
  if (message_count_ == 0 || log_time > message_end_time_) message_end_time_ = log_time;
  ++message_count_;

  if (chunk_.size() >= options_.chunk_size) return CloseChunk();
  return Status::OK();
}

Status Writer::Impl::CloseChunk() {
  if (chunk_.size() == 0) return Status::OK();
  const std::uint32_t crc = Crc32(0, chunk_.data(), chunk_.size());

  // Compress (or not) into `body`.
  iovec body = Iov(chunk_);
  const char* compression = "";
  if (options_.compression == Compression::kZstd) {
    compressed_.Reserve(ZSTD_compressBound(chunk_.size()));
    std::size_t n = ZSTD_compress2(zstd_.get(), compressed_.data(), compressed_.capacity(),
                                   chunk_.data(), chunk_.size());
    if (ZSTD_isError(n)) {
      return Fail(Status::IOError(path(), std::string("zstd compression failed: ") + ZSTD_getErrorName(n)));
    }
    body = {compressed_.data(), n};
    compression = "zstd";
  }

  codec::ChunkIndexRecord index;
  ChunkInfo& info = index.info;
  info.offset = pos_;
  info.message_start_time = chunk_start_time_;
  info.message_end_time = chunk_end_time_;
  info.compression = compression;
  info.compressed_size = body.iov_len;
  info.uncompressed_size = chunk_.size();

  chunk_prefix_.Clear();
  chunk_prefix_.PutU8(format::kChunk);
  const std::size_t compression_len = info.compression.size();
  chunk_prefix_.PutU64(8 + 8 + 8 + 4 + 4 + compression_len + 8 + body.iov_len);
  chunk_prefix_.PutU64(chunk_start_time_);
  chunk_prefix_.PutU64(chunk_end_time_);
  chunk_prefix_.PutU64(chunk_.size());
  chunk_prefix_.PutU32(crc);
  chunk_prefix_.PutString(info.compression);
  chunk_prefix_.PutU64(body.iov_len);
  info.length = chunk_prefix_.size() + body.iov_len;

  // MessageIndex records follow the chunk, one per channel that has messages in it.
  message_indexes_.Clear();
  index.message_index_offsets.reserve(chunk_channels_.size());
  for (ChannelId id : chunk_channels_) {
    auto& entries = states_[id - 1].index;
    index.message_index_offsets.emplace_back(id, info.offset + info.length + message_indexes_.size());
    const auto array_bytes = static_cast<std::uint32_t>(entries.size() * 16);
    message_indexes_.PutU8(format::kMessageIndex);
    message_indexes_.PutU64(2 + 4 + std::uint64_t{array_bytes});
    message_indexes_.PutU16(id);
    message_indexes_.PutU32(array_bytes);
    for (const auto& [time, offset] : entries) {
      message_indexes_.PutU64(time);
      message_indexes_.PutU64(offset);
    }
    entries.clear();
  }
  index.message_index_length = message_indexes_.size();
  chunk_channels_.clear();
  chunk_.Clear();

  const iovec parts[] = {Iov(chunk_prefix_), body, Iov(message_indexes_)};
  if (Status s = Emit(parts, true); !s.ok()) return s;
  chunk_indexes_.push_back(std::move(index));
  return Status::OK();
}

Status Writer::Impl::AddMetadata(std::string_view name, const std::map<std::string, std::string>& entries) {
  if (Status s = Usable("AddMetadata"); !s.ok()) return s;
  scratch_.Clear();
  codec::EncodeMetadata({std::string(name), entries}, &scratch_);
  codec::MetadataIndexRecord index{pos_, scratch_.size(), std::string(name)};
  iovec iov = Iov(scratch_);
  if (Status s = Emit({&iov, 1}, true); !s.ok()) return s;
  metadata_indexes_.push_back(std::move(index));
  return Status::OK();
}

Status Writer::Impl::Flush() {
  if (Status s = Usable("Flush"); !s.ok()) return s;
  if (Status s = CloseChunk(); !s.ok()) return s;
  if (options_.sync_on_flush) {
    if (Status s = file_.Sync(); !s.ok()) return Fail(s);
  }
  return Status::OK();
}

Status Writer::Impl::Close() {
  if (closed_) return close_status_;
  Status s = Usable("Close");
  if (s.ok()) s = CloseChunk();
  closed_ = true;
  if (!s.ok()) {
    file_.Close().IgnoreError();  // The first error is the one to report.
    return close_status_ = s;
  }

  // DataEnd, then the summary grouped by opcode, then the offsets of those groups.
  ByteBuffer& out = scratch_;
  out.Clear();
  codec::EncodeDataEnd(data_crc_, &out);
  const std::uint64_t summary_start = pos_ + out.size();
  std::vector<codec::SummaryOffsetRecord> groups;
  auto group = [&](std::uint8_t opcode, auto&& encode_all) {
    const std::size_t start = out.size();
    encode_all();
    if (out.size() > start) groups.push_back({opcode, pos_ + start, out.size() - start});
  };
  group(format::kSchema, [&] {
    for (const Schema& schema : schemas_) codec::EncodeSchema(schema, &out);
  });
  group(format::kChannel, [&] {
    for (const Channel& channel : channels_) codec::EncodeChannel(channel, &out);
  });
  group(format::kStatistics, [&] {
    Statistics stats;
    stats.message_count = message_count_;
    stats.schema_count = static_cast<std::uint16_t>(schemas_.size());
    stats.channel_count = static_cast<std::uint32_t>(channels_.size());
    stats.metadata_count = static_cast<std::uint32_t>(metadata_indexes_.size());
    stats.chunk_count = static_cast<std::uint32_t>(chunk_indexes_.size());
    stats.message_start_time = message_start_time_;
    stats.message_end_time = message_end_time_;
    for (const Channel& channel : channels_) {
      stats.channel_message_counts[channel.id] = states_[channel.id - 1].message_count;
    }
    codec::EncodeStatistics(stats, &out);
  });
  group(format::kChunkIndex, [&] {
    for (const auto& index : chunk_indexes_) codec::EncodeChunkIndex(index, &out);
  });
  group(format::kMetadataIndex, [&] {
    for (const auto& index : metadata_indexes_) codec::EncodeMetadataIndex(index, &out);
  });
  const std::uint64_t summary_offset_start = pos_ + out.size();
  for (const auto& g : groups) codec::EncodeSummaryOffset(g, &out);

  // The summary CRC covers the summary through the footer's summary_offset_start field.
  codec::EncodeFooterPrefix(summary_start, summary_offset_start, &out);
  const std::size_t summary_pos = static_cast<std::size_t>(summary_start - pos_);
  const std::uint32_t summary_crc = Crc32(0, out.data() + summary_pos, out.size() - summary_pos);
  out.PutU32(summary_crc);
  out.PutBytes(format::kMagic.data(), format::kMagic.size());

  iovec iov = Iov(out);
  s = Emit({&iov, 1}, false);
  if (s.ok()) s = file_.Close();
  return close_status_ = s;
}

Writer::Writer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Writer::Writer(Writer&&) noexcept = default;
Writer& Writer::operator=(Writer&&) noexcept = default;

Writer::~Writer() {
  if (impl_) impl_->Close().IgnoreError();  // a destructor cannot report: callers that care call Close()
}

StatusOr<Writer> Writer::Open(const std::string& path, const WriterOptions& options) {
  auto impl = std::make_unique<Impl>();
  if (Status s = impl->Open(path, options); !s.ok()) return s;
  return Writer(std::move(impl));
}

StatusOr<SchemaId> Writer::AddSchema(std::string_view name, std::string_view encoding,
                                     std::string_view data) {
  return impl_->AddSchema(name, encoding, data);
}

StatusOr<ChannelId> Writer::AddChannel(std::string_view topic, std::string_view message_encoding,
                                       SchemaId schema_id,
                                       const std::map<std::string, std::string>& metadata) {
  return impl_->AddChannel(topic, message_encoding, schema_id, metadata);
}

Status Writer::Write(ChannelId channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                     std::uint64_t publish_time_ns, std::span<const std::uint8_t> data) {
  return impl_->Write(channel_id, sequence, log_time_ns, publish_time_ns, data);
}

Status Writer::AddMetadata(std::string_view name, const std::map<std::string, std::string>& entries) {
  return impl_->AddMetadata(name, entries);
}

Status Writer::Flush() { return impl_->Flush(); }
Status Writer::Close() { return impl_->Close(); }
std::uint64_t Writer::bytes_written() const { return impl_->bytes_written(); }
std::uint64_t Writer::message_count() const { return impl_->message_count(); }
const std::string& Writer::path() const { return impl_->path(); }

}  // namespace dyad::mcap
