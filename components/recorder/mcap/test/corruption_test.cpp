// Damaged bytes are detected (chunk CRC, zstd frame, summary CRC, data-section CRC), never
// returned as good data.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

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
  ChunkInfo second;
  {
    auto intact = Reader::Open(file.path);
    ASSERT_TRUE(intact.ok());
    second = intact->chunks()[1];
  }
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
  ChunkInfo first;
  {
    auto intact = Reader::Open(file.path);
    ASSERT_TRUE(intact.ok());
    first = intact->chunks()[0];
  }
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
  ChunkInfo first;
  {
    auto intact = Reader::Open(file.path);
    ASSERT_TRUE(intact.ok());
    first = intact->chunks()[0];
  }
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
