// C++ writer -> C++ reader: every message, schema, channel and statistic comes back.
#include <gtest/gtest.h>

#include <algorithm>

#include "test_files.hpp"

namespace dyad::mcap {
namespace {

using testing::ReadAll;
using testing::TempPath;
using testing::TestMessage;
using testing::WriteChunkedFile;

WriterOptions Unchunked(Compression compression) {
  WriterOptions options;
  options.chunk_size = 1 << 20;  // Chunks close only at Flush().
  options.compression = compression;
  return options;
}

TEST(WriterReader, RoundTripsEveryMessageWithZstdChunks) {
  auto file = WriteChunkedFile(TempPath("f.mcap"), Unchunked(Compression::kZstd), 4, 30);
  auto reader = Reader::Open(file.path);
  ASSERT_TRUE(reader.ok()) << reader.status().ToString();
  EXPECT_TRUE(reader->recovery().used_summary);
  EXPECT_FALSE(reader->recovery().truncated);
  Status status;
  EXPECT_EQ(ReadAll(*reader, {}, &status), file.messages);
  EXPECT_TRUE(status.ok()) << status.ToString();
  ASSERT_EQ(reader->chunks().size(), 4u);
  EXPECT_EQ(reader->chunks()[0].compression, "zstd");
}

TEST(WriterReader, RoundTripsEveryMessageWithUncompressedChunks) {
  auto file = WriteChunkedFile(TempPath("f.mcap"), Unchunked(Compression::kNone), 3, 10);
  auto reader = Reader::Open(file.path);
  ASSERT_TRUE(reader.ok());
  EXPECT_EQ(ReadAll(*reader), file.messages);
  EXPECT_EQ(reader->chunks()[0].compression, "");
}

TEST(WriterReader, ReadsSchemasChannelsAndHeaderBack) {
  WriterOptions options = Unchunked(Compression::kZstd);
  options.profile = "";
  options.library = "dyad test";
  auto file = WriteChunkedFile(TempPath("f.mcap"), options, 1, 3);
  auto reader = Reader::Open(file.path);
  ASSERT_TRUE(reader.ok());
  EXPECT_EQ(reader->header().library, "dyad test");
  ASSERT_EQ(reader->schemas().size(), 1u);
  const Schema& schema = reader->schemas().at(1);
  EXPECT_EQ(schema.name, "dyad::msg::Pose2");
  EXPECT_EQ(schema.encoding, "omgidl");
  EXPECT_EQ(schema.data, testing::kPoseIdl);
  ASSERT_EQ(reader->channels().size(), 3u);
  const Channel& b = reader->channels().at(2);
  EXPECT_EQ(b.topic, "/b");
  EXPECT_EQ(b.message_encoding, "cdr");
  EXPECT_EQ(b.schema_id, 1);
  EXPECT_EQ(b.metadata.at("qos"), "reliable");
}

TEST(WriterReader, StatisticsCountEveryMessage) {
  auto file = WriteChunkedFile(TempPath("f.mcap"), Unchunked(Compression::kZstd), 5, 7);
  auto reader = Reader::Open(file.path);
  ASSERT_TRUE(reader.ok());
  const Statistics& s = reader->statistics();
  EXPECT_EQ(s.message_count, 35u);
  EXPECT_EQ(s.chunk_count, 5u);
  EXPECT_EQ(s.channel_count, 3u);
  EXPECT_EQ(s.schema_count, 1u);
  EXPECT_EQ(s.metadata_count, 1u);
  EXPECT_EQ(s.message_start_time, file.messages.front().log_time);
  EXPECT_EQ(s.message_end_time, file.messages.back().log_time);
  EXPECT_EQ(s.channel_message_counts.at(1), 12u);
  EXPECT_EQ(s.channel_message_counts.at(2), 12u);
  EXPECT_EQ(s.channel_message_counts.at(3), 11u);
}

TEST(WriterReader, LinearScanFindsWhatTheSummarySays) {
  auto file = WriteChunkedFile(TempPath("f.mcap"), Unchunked(Compression::kZstd), 5, 7);
  auto indexed = Reader::Open(file.path);
  ReaderOptions scan_options;
  scan_options.use_summary = false;
  auto scanned = Reader::Open(file.path, scan_options);
  ASSERT_TRUE(indexed.ok());
  ASSERT_TRUE(scanned.ok());
  EXPECT_FALSE(scanned->recovery().used_summary);
  EXPECT_FALSE(scanned->recovery().truncated);
  EXPECT_TRUE(scanned->recovery().data_complete);
  EXPECT_EQ(ReadAll(*scanned), ReadAll(*indexed));
  const Statistics& a = indexed->statistics();
  const Statistics& b = scanned->statistics();
  EXPECT_EQ(a.message_count, b.message_count);
  EXPECT_EQ(a.chunk_count, b.chunk_count);
  EXPECT_EQ(a.channel_message_counts, b.channel_message_counts);
  EXPECT_EQ(a.message_start_time, b.message_start_time);
  EXPECT_EQ(a.message_end_time, b.message_end_time);
  ASSERT_EQ(indexed->chunks().size(), scanned->chunks().size());
  for (std::size_t i = 0; i < indexed->chunks().size(); ++i) {
    EXPECT_EQ(indexed->chunks()[i].offset, scanned->chunks()[i].offset);
    EXPECT_EQ(indexed->chunks()[i].length, scanned->chunks()[i].length);
  }
}

TEST(WriterReader, ChunksCloseByThemselvesAtTheSizeThreshold) {
  WriterOptions options;
  options.chunk_size = 1024;
  const std::string path = TempPath("f.mcap");
  auto writer = Writer::Open(path, options);
  ASSERT_TRUE(writer.ok());
  auto channel = writer->AddChannel("/x", "cdr", 0);
  ASSERT_TRUE(channel.ok());
  const auto payload = testing::Payload(0, 48);
  for (std::uint32_t i = 0; i < 1000; ++i) ASSERT_TRUE(writer->Write(*channel, i, i, i, payload).ok());
  ASSERT_TRUE(writer->Close().ok());
  auto reader = Reader::Open(path);
  ASSERT_TRUE(reader.ok());
  // 79-byte records: 13 per 1 KiB chunk.
  EXPECT_EQ(reader->chunks().size(), (1000 + 12) / 13);
  EXPECT_EQ(ReadAll(*reader).size(), 1000u);
}

TEST(WriterReader, LogTimeOrderSortsAndFileOrderKeepsWritingOrder) {
  const std::string path = TempPath("f.mcap");
  auto writer = Writer::Open(path, Unchunked(Compression::kZstd));
  ASSERT_TRUE(writer.ok());
  auto channel = writer->AddChannel("/x", "cdr", 0);
  // Two chunks with overlapping, unordered log times.
  const std::uint64_t times[] = {50, 10, 30, 20, 60, 40, 10};
  for (std::uint32_t i = 0; i < 7; ++i) {
    ASSERT_TRUE(writer->Write(*channel, i, times[i], 0, {}).ok());
    if (i == 3) {
      ASSERT_TRUE(writer->Flush().ok());
    }
  }
  ASSERT_TRUE(writer->Close().ok());
  auto reader = Reader::Open(path);
  ASSERT_TRUE(reader.ok());
  std::vector<std::uint32_t> by_time, by_file;
  for (const auto& m : ReadAll(*reader)) by_time.push_back(m.sequence);
  ReadOptions file_order;
  file_order.order = ReadOptions::Order::kFile;
  for (const auto& m : ReadAll(*reader, file_order)) by_file.push_back(m.sequence);
  // Equal times (10) keep writing order: 1 before 6.
  EXPECT_EQ(by_time, (std::vector<std::uint32_t>{1, 6, 3, 2, 5, 0, 4}));
  EXPECT_EQ(by_file, (std::vector<std::uint32_t>{0, 1, 2, 3, 4, 5, 6}));
}

TEST(WriterReader, FiltersByTopicAndTimeRange) {
  auto file = WriteChunkedFile(TempPath("f.mcap"), Unchunked(Compression::kZstd), 4, 30);
  auto reader = Reader::Open(file.path);
  ASSERT_TRUE(reader.ok());
  ReadOptions options;
  options.topics = {"/b"};
  options.start_time = file.messages[40].log_time;
  options.end_time = file.messages[80].log_time;
  std::vector<TestMessage> expected;
  for (std::size_t i = 40; i <= 80; ++i) {
    if (file.messages[i].topic == "/b") expected.push_back(file.messages[i]);
  }
  EXPECT_EQ(ReadAll(*reader, options), expected);
}

TEST(WriterReader, VisitorCanStopEarly) {
  auto file = WriteChunkedFile(TempPath("f.mcap"), Unchunked(Compression::kZstd), 3, 10);
  auto reader = Reader::Open(file.path);
  ASSERT_TRUE(reader.ok());
  int seen = 0;
  Status s = reader->ReadMessages({}, [&](const MessageView&) { return ++seen < 5; });
  EXPECT_TRUE(s.ok());
  EXPECT_EQ(seen, 5);
}

TEST(WriterReader, EmptyRecordingHasASummaryAndNoMessages) {
  const std::string path = TempPath("empty.mcap");
  {
    auto writer = Writer::Open(path);
    ASSERT_TRUE(writer.ok());
    ASSERT_TRUE(writer->Close().ok());
  }
  auto reader = Reader::Open(path);
  ASSERT_TRUE(reader.ok()) << reader.status().ToString();
  EXPECT_TRUE(reader->recovery().used_summary);
  EXPECT_EQ(reader->statistics().message_count, 0u);
  EXPECT_TRUE(reader->chunks().empty());
  EXPECT_TRUE(ReadAll(*reader).empty());
  EXPECT_TRUE(reader->VerifyDataCrc().ok());
}

TEST(WriterReader, DataSectionCrcVerifies) {
  auto file = WriteChunkedFile(TempPath("f.mcap"), Unchunked(Compression::kZstd), 3, 10);
  auto reader = Reader::Open(file.path);
  ASSERT_TRUE(reader.ok());
  Status s = reader->VerifyDataCrc();
  EXPECT_TRUE(s.ok()) << s.ToString();
}

TEST(WriterReader, DestructorFinishesTheFile) {
  const std::string path = TempPath("f.mcap");
  {
    auto writer = Writer::Open(path);
    ASSERT_TRUE(writer.ok());
    auto channel = writer->AddChannel("/x", "cdr", 0);
    ASSERT_TRUE(writer->Write(*channel, 0, 1, 1, testing::Payload(0, 8)).ok());
  }
  auto reader = Reader::Open(path);
  ASSERT_TRUE(reader.ok());
  EXPECT_TRUE(reader->recovery().used_summary);
  EXPECT_EQ(ReadAll(*reader).size(), 1u);
}

TEST(Writer, SameSchemaTwiceGetsTheSameId) {
  auto writer = Writer::Open(TempPath("f.mcap"));
  ASSERT_TRUE(writer.ok());
  auto a = writer->AddSchema("T", "omgidl", "struct T { long x; };");
  auto b = writer->AddSchema("T", "omgidl", "struct T { long x; };");
  auto c = writer->AddSchema("U", "omgidl", "struct U { long x; };");
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  EXPECT_EQ(*a, 1);
  EXPECT_EQ(*b, 1);
  EXPECT_EQ(*c, 2);
}

TEST(Writer, UnknownIdsAreInvalidArgumentsNamingTheFile) {
  const std::string path = TempPath("f.mcap");
  auto writer = Writer::Open(path);
  ASSERT_TRUE(writer.ok());
  Status s = writer->Write(7, 0, 0, 0, {});
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(s.message(), path + ": Write: unknown channel id 7");
  auto channel = writer->AddChannel("/x", "cdr", 3);
  ASSERT_FALSE(channel.ok());
  EXPECT_EQ(channel.status().message(), path + ": AddChannel(\"/x\"): unknown schema id 3");
}

TEST(Writer, CallsAfterCloseFail) {
  auto writer = Writer::Open(TempPath("f.mcap"));
  ASSERT_TRUE(writer.ok());
  auto channel = writer->AddChannel("/x", "cdr", 0);
  ASSERT_TRUE(writer->Close().ok());
  EXPECT_TRUE(writer->Close().ok());  // Idempotent.
  EXPECT_EQ(writer->Write(*channel, 0, 0, 0, {}).code(), Status::Code::kFailedPrecondition);
  EXPECT_EQ(writer->Flush().code(), Status::Code::kFailedPrecondition);
}

TEST(Writer, OpenFailureNamesThePath) {
  auto writer = Writer::Open("/nonexistent-dir/x.mcap");
  ASSERT_FALSE(writer.ok());
  EXPECT_EQ(writer.status().code(), Status::Code::kIOError);
  EXPECT_EQ(writer.status().message().rfind("/nonexistent-dir/x.mcap: create: ", 0), 0u)
      << writer.status().message();
}

TEST(Reader, RejectsAFileThatIsNotMcap) {
  const std::string path = TempPath("not.mcap");
  FILE* f = std::fopen(path.c_str(), "wb");
  std::fputs("hello, this is not an MCAP file at all", f);
  std::fclose(f);
  auto reader = Reader::Open(path);
  ASSERT_FALSE(reader.ok());
  EXPECT_EQ(reader.status().code(), Status::Code::kDataLoss);
  EXPECT_EQ(reader.status().message(), path + ": not an MCAP file (wrong magic bytes)");
}

TEST(Reader, MissingFileIsAnIOErrorNamingIt) {
  auto reader = Reader::Open("/nonexistent-dir/x.mcap");
  ASSERT_FALSE(reader.ok());
  EXPECT_EQ(reader.status().code(), Status::Code::kIOError);
  EXPECT_NE(reader.status().message().find("/nonexistent-dir/x.mcap"), std::string::npos);
}

}  // namespace
}  // namespace dyad::mcap
