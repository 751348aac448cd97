// Damaged bytes are detected (chunk CRC, zstd frame, summary CRC, data-section CRC), never
// returned as good data.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "test_files.hpp"

namespace dyad::mcap {
namespace {

using testing::ReadAll;
using testing::TempPath;

WriterOptions FlushDelimited(Compression compression) {
  WriterOptions options;
  options.chunk_size = 1 << 20;
  options.compression = compression;
  return options;
}

TEST(Corruption, FlippedByteInAnUncompressedChunkFailsItsCrc) {
  auto file = testing::WriteChunkedFile(TempPath("f.mcap"), FlushDelimited(Compression::kNone), 3, 10);
  const std::vector<ChunkInfo> chunks = testing::Chunks(file.path);
  ASSERT_EQ(chunks.size(), 3u);
  const ChunkInfo second = chunks[1];
  testing::FlipByte(file.path, second.offset + second.length - 5);  // Inside the last payload.
  auto reader = Reader::Open(file.path);
  ASSERT_TRUE(reader.ok());
  Status status;
  auto messages = ReadAll(*reader, {}, &status);
  EXPECT_EQ(status.code(), Status::Code::kDataLoss);
  EXPECT_EQ(status.message().rfind(file.path + ": chunk at offset " + std::to_string(second.offset) +
                                   ": CRC mismatch (stored 0x", 0), 0u)
      << status.message();
  EXPECT_EQ(messages.size(), 10u);  // The first chunk was delivered before the damage.

  std::uint64_t skipped = 0;
  ReadOptions skip;
  skip.skip_damaged = true;
  skip.skipped_chunks = &skipped;
  messages = ReadAll(*reader, skip, &status);
  EXPECT_TRUE(status.ok());
  EXPECT_EQ(skipped, 1u);
  EXPECT_EQ(messages.size(), 20u);
}

TEST(Corruption, FlippedByteInAZstdChunkIsDataLoss) {
  auto file = testing::WriteChunkedFile(TempPath("f.mcap"), FlushDelimited(Compression::kZstd), 3, 10);
  const std::vector<ChunkInfo> chunks = testing::Chunks(file.path);
  ASSERT_EQ(chunks.size(), 3u);
  const ChunkInfo first = chunks[0];
  testing::FlipByte(file.path, first.offset + first.length - first.compressed_size / 2);
  auto reader = Reader::Open(file.path);
  ASSERT_TRUE(reader.ok());
  Status status;
  auto messages = ReadAll(*reader, {}, &status);
  EXPECT_EQ(status.code(), Status::Code::kDataLoss) << status.ToString();
  EXPECT_TRUE(messages.empty());
}

TEST(Corruption, LinearScanListsDamagedChunksAndReadsTheRest) {
  auto file = testing::WriteChunkedFile(TempPath("f.mcap"), FlushDelimited(Compression::kNone), 3, 10);
  const std::vector<ChunkInfo> chunks = testing::Chunks(file.path);
  ASSERT_EQ(chunks.size(), 3u);
  const ChunkInfo first = chunks[0];
  testing::FlipByte(file.path, first.offset + first.length - 5);
  const auto size = std::filesystem::file_size(file.path);
  ASSERT_EQ(::truncate(file.path.c_str(), static_cast<off_t>(size - 10)), 0);  // Forces a scan.
  auto reader = Reader::Open(file.path);
  ASSERT_TRUE(reader.ok());
  const Recovery& r = reader->recovery();
  ASSERT_EQ(r.damaged_chunks.size(), 1u);
  EXPECT_EQ(r.damaged_chunks.begin()->first, first.offset);
  EXPECT_EQ(r.damaged_chunks.begin()->second.rfind("CRC mismatch", 0), 0u);
  Status status;
  ReadAll(*reader, {}, &status);
  EXPECT_EQ(status.code(), Status::Code::kDataLoss);
  ReadOptions skip;
  skip.skip_damaged = true;
  EXPECT_EQ(ReadAll(*reader, skip, &status).size(), 20u);
  EXPECT_TRUE(status.ok());
}

// Chunk record layout: opcode, length, start time, end time, uncompressed size, CRC, ...
constexpr std::uint64_t kChunkUncompressedSizeAt = 1 + 8 + 8 + 8;
constexpr std::uint64_t kChunkCrcAt = kChunkUncompressedSizeAt + 8;
// ... compression (empty: its length only), records size, then the records.
constexpr std::uint64_t kChunkRecordsAt = kChunkCrcAt + 4 + 4 + 8;

TEST(Corruption, DamagedSizeFieldIsDataLossNotAHugeAllocation) {
  for (Compression compression : {Compression::kZstd, Compression::kNone}) {
    auto file = testing::WriteChunkedFile(TempPath("f.mcap"), FlushDelimited(compression), 3, 10);
    const std::vector<ChunkInfo> chunks = testing::Chunks(file.path);
    ASSERT_EQ(chunks.size(), 3u);
    const std::uint64_t three_gib = std::uint64_t{3} << 30;
    testing::OverwriteU64(file.path, chunks[0].offset + kChunkUncompressedSizeAt, three_gib);
    auto reader = Reader::Open(file.path);
    ASSERT_TRUE(reader.ok());
    Status status;
    EXPECT_TRUE(ReadAll(*reader, {}, &status).empty());
    EXPECT_EQ(status.code(), Status::Code::kDataLoss);
    const std::string expected = file.path + ": chunk at offset " + std::to_string(chunks[0].offset) +
                                 ": declared uncompressed size 3221225472 differs from the " +
                                 (compression == Compression::kZstd ? "zstd frame's " : "") +
                                 std::to_string(chunks[0].uncompressed_size) +
                                 (compression == Compression::kZstd ? " bytes" : " bytes stored");
    EXPECT_EQ(status.message(), expected);
  }
}

// Found by fuzzing (tests/fuzz/regressions/mcap/zstd_chunk_claims_4_gib, cut short so that the
// scan reads it): a zstd chunk whose frame states no content size and whose record claims just
// under 4 GiB was allocated at that size before zstd could say the bytes do not hold it. The claim
// is now checked against what its compressed bytes can expand to first.
TEST(Corruption, ZstdChunkClaimingMoreThanItsBytesCanHoldIsDamagedNotAllocated) {
  std::ifstream in(DYAD_FUZZ_REGRESSIONS "/mcap/zstd_chunk_claims_4_gib", std::ios::binary);
  const std::string input{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  ASSERT_GT(input.size(), 1u);
  const std::string path = TempPath("claims.mcap");
  std::ofstream(path, std::ios::binary) << input.substr(1);  // byte 0: the fuzz harness's options
  auto reader = Reader::Open(path);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  ASSERT_EQ(reader->recovery().damaged_chunks.size(), 1u);
  const std::string& why = reader->recovery().damaged_chunks.begin()->second;
  EXPECT_NE(why.find("declared uncompressed size "), std::string::npos) << why;
  EXPECT_NE(why.find(" zstd bytes can hold"), std::string::npos) << why;
  std::filesystem::remove(path);
}

TEST(Corruption, ScanCountsNoMessageOfAMisframedChunk) {
  auto file = testing::WriteChunkedFile(TempPath("f.mcap"), FlushDelimited(Compression::kNone), 3, 10);
  const std::vector<ChunkInfo> chunks = testing::Chunks(file.path);
  ASSERT_EQ(chunks.size(), 3u);
  // Without a CRC (other writers may leave it 0) only the framing betrays the second message's
  // damaged length; the first message of that chunk must not be counted either.
  testing::OverwriteU32(file.path, chunks[1].offset + kChunkCrcAt, 0);
  const std::uint64_t first_message_length = file.messages[0].data.size() + 2 + 4 + 8 + 8;
  testing::FlipByte(file.path, chunks[1].offset + kChunkRecordsAt + 1 + 8 + first_message_length + 1 + 7);
  ReaderOptions scan;
  scan.use_summary = false;
  auto reader = Reader::Open(file.path, scan);
  ASSERT_TRUE(reader.ok());
  ASSERT_EQ(reader->recovery().damaged_chunks.count(chunks[1].offset), 1u);
  EXPECT_EQ(reader->recovery().damaged_chunks.at(chunks[1].offset), "records inside the chunk are misframed");
  const Statistics& stats = reader->statistics();
  EXPECT_EQ(stats.message_count, 20u);
  EXPECT_EQ(stats.channel_message_counts.at(1) + stats.channel_message_counts.at(2) +
                stats.channel_message_counts.at(3),
            20u);
  EXPECT_EQ(stats.message_end_time, file.messages.back().log_time);
}

TEST(Corruption, DamagedSummaryFallsBackToALinearScan) {
  auto file = testing::WriteChunkedFile(TempPath("f.mcap"), FlushDelimited(Compression::kZstd), 3, 10);
  const auto size = std::filesystem::file_size(file.path);
  testing::FlipByte(file.path, size - 60);  // In the summary offsets, before the footer.
  auto reader = Reader::Open(file.path);
  ASSERT_TRUE(reader.ok());
  EXPECT_FALSE(reader->recovery().used_summary);
  EXPECT_EQ(reader->recovery().summary_problem, "summary CRC mismatch");
  EXPECT_FALSE(reader->recovery().truncated);
  EXPECT_EQ(ReadAll(*reader), file.messages);
}

TEST(Corruption, DataSectionCrcCatchesAChangedSchema) {
  auto file = testing::WriteChunkedFile(TempPath("f.mcap"), FlushDelimited(Compression::kZstd), 2, 5);
  testing::FlipByte(file.path, 100);  // Inside the Schema record's IDL text.
  auto reader = Reader::Open(file.path);
  ASSERT_TRUE(reader.ok());
  Status s = reader->VerifyDataCrc();
  EXPECT_EQ(s.code(), Status::Code::kDataLoss);
  EXPECT_NE(s.message().find("data-section CRC mismatch"), std::string::npos);
}

}  // namespace
}  // namespace dyad::mcap
