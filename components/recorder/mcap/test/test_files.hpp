// Helpers shared by the dyad_mcap tests: temporary paths, a standard recording, reading it back.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dyad/mcap/reader.hpp"
#include "dyad/mcap/writer.hpp"

namespace dyad::mcap::testing {

struct TestMessage {
  std::string topic;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;
  std::uint64_t publish_time = 0;
  std::vector<std::uint8_t> data;
  bool operator==(const TestMessage&) const = default;
};

// A fresh path in the test's temporary directory, unique per test and name.
std::string TempPath(const std::string& name);

// The IDL text used as the schema of the test channels.
extern const char* const kPoseIdl;

struct WrittenFile {
  std::string path;
  std::vector<TestMessage> messages;  // In writing order.
};

// Writes `chunks` chunks of `per_chunk` messages each, round-robin over the topics /a, /b, /c
// (one omgidl schema, cdr encoding), calling Flush() after each chunk so chunk k holds exactly
// messages [k * per_chunk, (k + 1) * per_chunk). A Metadata record comes before the first chunk.
// options.chunk_size should be large enough that no chunk closes by itself.
WrittenFile WriteChunkedFile(const std::string& path, const WriterOptions& options, int chunks,
                             int per_chunk);

// A deterministic payload of `size` bytes for message `i` (a CDR header, then varying bytes).
std::vector<std::uint8_t> Payload(std::uint32_t i, std::size_t size);

// Every message of `reader` with the given options; sets *status (may be null) to the result.
std::vector<TestMessage> ReadAll(const Reader& reader, const ReadOptions& options = {},
                                 Status* status = nullptr);

// The chunks of an intact file, as its summary lists them (fails the test if it cannot be read).
std::vector<ChunkInfo> Chunks(const std::string& path);

// Overwrites one byte of a file (XORs it with 0xFF).
void FlipByte(const std::string& path, std::uint64_t offset);
// Overwrites a little-endian field of a file.
void OverwriteU32(const std::string& path, std::uint64_t offset, std::uint32_t value);
void OverwriteU64(const std::string& path, std::uint64_t offset, std::uint64_t value);

}  // namespace dyad::mcap::testing
