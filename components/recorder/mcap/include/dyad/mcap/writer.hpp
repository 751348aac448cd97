// dyad::mcap::Writer: writes an MCAP file (chunked, optionally zstd-compressed, fully indexed).
//
// Contract:
//   - Open(path, options) creates or truncates `path` and writes the magic and Header at once.
//   - AddSchema / AddChannel / AddMetadata write their record to the data section immediately
//     (outside any chunk), so they always precede the chunks whose messages use them, and they are
//     on disk even if the process dies right after.
//   - Write() appends one Message record to the chunk being filled in memory. When that chunk
//     reaches `WriterOptions::chunk_size` uncompressed bytes it is compressed, its CRC32 computed,
//     and it is handed to the kernel together with its MessageIndex records in one writev(2).
//     Consequence: a process killed at any point loses at most the chunk still in memory; the file
//     is readable by dyad::mcap::Reader up to the last complete chunk.
//   - Flush() closes the current chunk now (even if small). The recorder calls it on SIGINT and
//     periodically to bound what a crash can lose in time as well as in bytes. Flush() is not
//     async-signal-safe: a signal handler sets a flag, the writing thread calls Flush().
//   - Close() closes the last chunk and writes DataEnd (with the data-section CRC32), the summary
//     section (Schema, Channel, Statistics, ChunkIndex, MetadataIndex records, grouped by opcode),
//     the SummaryOffset section, the Footer (with the summary CRC32) and the closing magic.
//     The destructor calls Close() if needed and drops its Status: call Close() to see errors.
//   - Errors: no exception escapes; each call returns a Status naming the file. After an I/O error
//     the writer is failed: every later call returns that first error.
//   - Steady state does not allocate: Write() copies into a buffer that keeps its capacity across
//     chunks; per-channel message indexes keep theirs too.
//   - Not thread-safe: one thread writes (the recorder's writer thread).
//
// Usage:
//   dyad::StatusOr<dyad::mcap::Writer> w = dyad::mcap::Writer::Open("run.mcap", {});
//   if (!w.ok()) return w.status();
//   dyad::StatusOr<dyad::mcap::SchemaId> schema =
//       w->AddSchema("dyad::msg::Pose2", "omgidl", idl_text);
//   dyad::StatusOr<dyad::mcap::ChannelId> channel =
//       w->AddChannel("/robot/pose", "cdr", *schema, {});
//   w->Write(*channel, seq, receive_ns, source_ns, cdr_bytes);
//   w->AddMetadata("dyad.graph", {{"yaml", graph_text}});
//   dyad::Status s = w->Close();
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "dyad/mcap/records.hpp"
#include "dyad/status.hpp"

namespace dyad::mcap {

enum class Compression {
  kNone,  // Chunks stored as is ("" in the file).
  kZstd,  // Chunks compressed with zstd ("zstd" in the file).
};

struct WriterOptions {
  // MCAP profile in the Header. Default: "" (dyad's omgidl + cdr has no well-known profile).
  std::string profile;
  // Writer identification in the Header.
  std::string library = "dyad_mcap 0.1";
  // A chunk is closed once its uncompressed records reach this many bytes. Smaller loses less on a
  // crash and lets readers seek finer; larger compresses a little better. REQUIRES: 1 KiB .. 1 GiB.
  // Default: 256 KiB: at 100,000 samples/s of 48 bytes a chunk fills in ~33 ms, which bounds what a
  // crash loses; bench/mcap measures millions of samples/s anywhere from 64 KiB to 1 MiB.
  std::uint64_t chunk_size = 256 * 1024;
  // Default: kZstd.
  Compression compression = Compression::kZstd;
  // zstd level, used when compression == kZstd. REQUIRES: 1 .. 19. Default: 1 (fastest; on small
  // CDR samples higher levels gain little ratio for much more time).
  int zstd_level = 1;
  // Flush() also calls fdatasync(2), so flushed data survives power loss, not only a crash.
  // Costs milliseconds per call. Default: false.
  bool sync_on_flush = false;
  // The file holds a subject's data: it is created 0600, never through a symlink
  // (dyad/private_file.hpp). false: `path` must not exist (the check and the creation are one
  // step); true: an existing file or link at `path` is replaced (a new file renamed onto it, so
  // a link's target is never touched). Default: false.
  bool replace_existing = false;

  // Ok, or InvalidArgument naming the field, its value and the broken constraint.
  Status Validate() const;
};

class Writer {
 public:
  // Creates `path` (0600; see replace_existing) and writes magic + Header.
  // Fails: InvalidArgument (bad options), FailedPrecondition (`path` exists, or is a symlink,
  // and replace_existing is false), IOError (cannot create).
  static StatusOr<Writer> Open(const std::string& path, const WriterOptions& options = {});

  Writer(Writer&&) noexcept;
  Writer& operator=(Writer&&) noexcept;
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;
  ~Writer();

  // Registers a schema; returns its id (1, 2, ...). `data` is the schema text (e.g. IDL) or bytes.
  // Adding the same (name, encoding, data) twice returns the first id.
  StatusOr<SchemaId> AddSchema(std::string_view name, std::string_view encoding, std::string_view data);

  // Registers a channel; returns its id (1, 2, ...). `schema_id` is 0 (no schema) or an id
  // returned by AddSchema (else InvalidArgument).
  StatusOr<ChannelId> AddChannel(std::string_view topic, std::string_view message_encoding,
                                 SchemaId schema_id,
                                 const std::map<std::string, std::string>& metadata = {});

  // Appends one message. `channel_id` must come from AddChannel (else InvalidArgument).
  // `log_time_ns`: when the recorder received it; `publish_time_ns`: the source timestamp (pass
  // log_time_ns when unknown). `data` is copied; it may be empty.
  Status Write(ChannelId channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
               std::uint64_t publish_time_ns, std::span<const std::uint8_t> data);

  // Writes a Metadata record (e.g. name "dyad.graph", {{"yaml", text}}).
  Status AddMetadata(std::string_view name, const std::map<std::string, std::string>& entries);

  // Closes the chunk being filled (if any) and hands it to the kernel (and the disk, if
  // sync_on_flush). Afterwards every message written so far is in a complete chunk in the file.
  Status Flush();

  // Finishes the file (see the contract above). Idempotent: a second call returns the first result.
  Status Close();

  // Bytes handed to the kernel so far (the file's size if the process died now).
  std::uint64_t bytes_written() const;
  // Messages written so far, including those in the chunk still in memory.
  std::uint64_t message_count() const;
  const std::string& path() const;

 private:
  class Impl;
  explicit Writer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace dyad::mcap
