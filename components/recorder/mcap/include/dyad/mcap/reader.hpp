// dyad::mcap::Reader: reads MCAP files, including ones cut short by a crash.
//
// Contract:
//   - Open(path) first tries the fast path: trailing magic + Footer -> summary section (its CRC is
//     checked when non-zero) -> Schema, Channel, Statistics, ChunkIndex, MetadataIndex records.
//     Messages are then read chunk by chunk through the chunk indexes.
//   - When the footer or summary is absent or damaged (a file cut short, a writer killed), Open
//     falls back to a linear scan from the start: it reads records one after another, decompresses
//     every chunk and checks its CRC32, collects schemas, channels, metadata and statistics, and
//     stops at the first record that does not fit in the file. recovery() says which path was
//     taken, whether the file was cut short, and the offset up to which it is valid.
//     A truncated file yields exactly the messages of the chunks that are complete before the cut.
//   - A chunk whose CRC32 does not match, that does not decompress, or whose declared size
//     disagrees with its stored bytes (checked before anything is allocated) is damaged: ReadMessages
//     fails with DataLoss naming the file and the chunk's offset, unless ReadOptions::skip_damaged
//     is set, in which case the chunk is skipped and counted. Chunks a scan already found damaged
//     (recovery().damaged_chunks) make ReadMessages fail before delivering anything, likewise.
//   - Supported: chunks compressed with "zstd" or stored uncompressed (""). Messages written
//     outside chunks (allowed by the specification, never written by dyad) are counted in
//     recovery().loose_messages during a scan but not returned.
//   - Errors: no exception escapes; Status messages begin with the file's path.
//   - A Reader is movable, not copyable; const methods may be called from several threads only if
//     they do not run at the same time (ReadMessages uses internal buffers).
//
// Usage:
//   dyad::StatusOr<dyad::mcap::Reader> r = dyad::mcap::Reader::Open("run.mcap");
//   if (!r.ok()) return r.status();
//   if (r->recovery().truncated) std::cerr << r->recovery().Describe() << "\n";
//   dyad::Status s = r->ReadMessages({}, [](const dyad::mcap::MessageView& m) {
//     std::cout << m.channel->topic << " " << m.log_time << "\n";
//     return true;  // false stops early
//   });
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "dyad/mcap/records.hpp"
#include "dyad/status.hpp"

namespace dyad::mcap {

struct ReaderOptions {
  // Use the summary section when present and intact. false forces the linear scan (for tests and
  // `dyad bag info --scan`). Default: true.
  bool use_summary = true;
};

// How Open() got its information and what it found missing.
struct Recovery {
  bool used_summary = false;  // Fast path taken.
  std::string summary_problem;  // Why the summary was not used ("" when it was).
  // The file does not end with a Footer and the closing magic (killed writer, cut copy).
  bool truncated = false;
  // The scan reached DataEnd: no message data is missing even if the file is truncated.
  bool data_complete = false;
  std::uint64_t file_size = 0;
  // End offset of the last complete record the scan accepted (== file_size on the fast path).
  std::uint64_t valid_up_to = 0;
  // Why the scan stopped, e.g. "Chunk record at offset 1234 needs 5678 bytes, file ends at 4000".
  std::string stop_reason;
  // Offsets of chunks found damaged during a scan (CRC mismatch or undecodable), with why.
  std::map<std::uint64_t, std::string> damaged_chunks;
  std::uint64_t loose_messages = 0;  // Message records outside chunks (not returned).

  // One line for people, e.g. "cut short: recovered 12 chunks up to byte 40960 of 41000 (...)".
  std::string Describe() const;
};

struct ReadOptions {
  enum class Order {
    kLogTime,  // Ascending log time across all chosen channels (ties keep file order).
    kFile,     // As stored: chunk by chunk, in writing order.
  };
  Order order = Order::kLogTime;
  // Only these topics; empty means all.
  std::set<std::string> topics;
  // Only messages with start_time <= log_time <= end_time.
  std::uint64_t start_time = 0;
  std::uint64_t end_time = UINT64_MAX;
  // Skip damaged chunks (counting them in *skipped_chunks if given) instead of failing.
  bool skip_damaged = false;
  std::uint64_t* skipped_chunks = nullptr;  // Not owned; may be null.
};

class Reader {
 public:
  // Opens `path`. Fails: IOError (cannot open/read), InvalidArgument (not a regular file, e.g. a
  // directory), DataLoss (not an MCAP file: wrong magic or an unreadable Header). A file cut short
  // succeeds, with recovery().truncated set.
  static StatusOr<Reader> Open(const std::string& path, const ReaderOptions& options = {});

  Reader(Reader&&) noexcept;
  Reader& operator=(Reader&&) noexcept;
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;
  ~Reader();

  const std::string& path() const;
  const Header& header() const;
  const std::map<SchemaId, Schema>& schemas() const;
  const std::map<ChannelId, Channel>& channels() const;
  const std::vector<Metadata>& metadata() const;
  // From the Statistics record, or recomputed by the scan (then for the complete chunks only).
  const Statistics& statistics() const;
  // Chunks in file order (undamaged ones only after a scan).
  const std::vector<ChunkInfo>& chunks() const;
  const Recovery& recovery() const;

  // Calls `visit` for each chosen message, in the chosen order, until it returns false.
  // Fails: DataLoss (damaged chunk unless skip_damaged; message on an unknown channel),
  // IOError. Messages delivered before a failure stay delivered.
  Status ReadMessages(const ReadOptions& options,
                      const std::function<bool(const MessageView&)>& visit) const;

  // Recomputes the data-section CRC32 stored in DataEnd (reads the whole data section).
  // Fails: FailedPrecondition when the file has no DataEnd with a CRC, DataLoss on mismatch.
  Status VerifyDataCrc() const;

 private:
  class Impl;
  explicit Reader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace dyad::mcap
