// A file cut short at any byte stays readable up to its last complete chunk.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>

#include "test_files.hpp"

namespace dyad::mcap {
namespace {

using testing::ReadAll;
using testing::TempPath;
using testing::TestMessage;

WriterOptions FlushDelimited() {
  WriterOptions options;
  options.chunk_size = 1 << 20;  // Chunks close only at Flush().
  return options;
}

TEST(Truncation, EveryCutKeepsExactlyTheMessagesOfTheCompleteChunks) {
  constexpr int kPerChunk = 4;
  auto file = testing::WriteChunkedFile(TempPath("full.mcap"), FlushDelimited(), 5, kPerChunk);
  std::vector<std::uint64_t> chunk_ends;
  for (const ChunkInfo& c : testing::Chunks(file.path)) chunk_ends.push_back(c.offset + c.length);
  ASSERT_EQ(chunk_ends.size(), 5u);
  const std::string cut_path = TempPath("cut.mcap");
  std::filesystem::copy_file(file.path, cut_path);
  const auto size = std::filesystem::file_size(file.path);
  // Cutting from the end down reuses one file: each truncate(2) shortens it by one byte.
  for (std::uint64_t cut = size - 1;; --cut) {
    ASSERT_EQ(::truncate(cut_path.c_str(), static_cast<off_t>(cut)), 0);
    auto reader = Reader::Open(cut_path);
    ASSERT_TRUE(reader.ok()) << "cut at " << cut << ": " << reader.status().ToString();
    const Recovery& r = reader->recovery();
    EXPECT_TRUE(r.truncated) << "cut at " << cut;
    EXPECT_FALSE(r.used_summary) << "cut at " << cut;
    EXPECT_LE(r.valid_up_to, cut);
    std::size_t complete = 0;
    while (complete < chunk_ends.size() && chunk_ends[complete] <= cut) ++complete;
    std::vector<TestMessage> expected(file.messages.begin(), file.messages.begin() + complete * kPerChunk);
    Status status;
    EXPECT_EQ(ReadAll(*reader, {}, &status), expected) << "cut at " << cut << ": " << r.Describe();
    EXPECT_TRUE(status.ok()) << status.ToString();
    EXPECT_EQ(reader->statistics().message_count, expected.size()) << "cut at " << cut;
    if (cut == 0) break;
  }
}

TEST(Truncation, ReportsWhereItStoppedAndWhy) {
  auto file = testing::WriteChunkedFile(TempPath("f.mcap"), FlushDelimited(), 3, 10);
  const std::vector<ChunkInfo> chunks = testing::Chunks(file.path);
  ASSERT_EQ(chunks.size(), 3u);
  const std::uint64_t second_chunk = chunks[1].offset, second_end = chunks[1].offset + chunks[1].length;
  const std::uint64_t cut = second_chunk + 20;
  ASSERT_EQ(::truncate(file.path.c_str(), static_cast<off_t>(cut)), 0);
  auto reader = Reader::Open(file.path);
  ASSERT_TRUE(reader.ok());
  const Recovery& r = reader->recovery();
  EXPECT_TRUE(r.truncated);
  EXPECT_FALSE(r.data_complete);
  EXPECT_EQ(r.valid_up_to, second_chunk);  // The first chunk's MessageIndex records end there.
  EXPECT_EQ(r.stop_reason, "Chunk record at offset " + std::to_string(second_chunk) + " needs " +
                               std::to_string(second_end - second_chunk) + " bytes, file ends at " +
                               std::to_string(cut));
  EXPECT_NE(r.Describe().find("cut short"), std::string::npos) << r.Describe();
  EXPECT_EQ(reader->chunks().size(), 1u);
  EXPECT_EQ(reader->metadata().size(), 1u);  // Written before the first chunk.
}

TEST(Truncation, LosingOnlyTheSummaryLosesNoMessages) {
  auto file = testing::WriteChunkedFile(TempPath("f.mcap"), FlushDelimited(), 3, 10);
  const auto size = std::filesystem::file_size(file.path);
  ASSERT_EQ(::truncate(file.path.c_str(), static_cast<off_t>(size - 30)), 0);
  auto reader = Reader::Open(file.path);
  ASSERT_TRUE(reader.ok());
  EXPECT_TRUE(reader->recovery().truncated);
  EXPECT_TRUE(reader->recovery().data_complete);
  EXPECT_EQ(ReadAll(*reader), file.messages);
  EXPECT_TRUE(reader->VerifyDataCrc().ok());
}

TEST(Truncation, ZeroByteFileIsAnEmptyTruncatedRecording) {
  const std::string path = TempPath("zero.mcap");
  FILE* f = std::fopen(path.c_str(), "wb");
  std::fclose(f);
  auto reader = Reader::Open(path);
  ASSERT_TRUE(reader.ok()) << reader.status().ToString();
  EXPECT_TRUE(reader->recovery().truncated);
  EXPECT_TRUE(ReadAll(*reader).empty());
}

// The real crash: a writer process killed with SIGKILL after some Flush() calls.
TEST(Truncation, FileOfAKilledWriterHoldsEveryFlushedMessage) {
  const std::string path = TempPath("killed.mcap");
  constexpr std::uint32_t kFlushed = 3000;
  pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    auto writer = Writer::Open(path);
    if (!writer.ok()) ::_exit(2);
    auto channel = writer->AddChannel("/x", "cdr", 0);
    const auto payload = testing::Payload(1, 48);
    for (std::uint32_t i = 0; i < kFlushed + 500; ++i) {
      if (!writer->Write(*channel, i, i, i, payload).ok()) ::_exit(3);
      if (i + 1 == kFlushed && !writer->Flush().ok()) ::_exit(4);
    }
    ::raise(SIGKILL);  // Dies with 500 messages in its open chunk.
    ::_exit(5);
  }
  int wstatus = 0;
  ASSERT_EQ(::waitpid(child, &wstatus, 0), child);
  ASSERT_TRUE(WIFSIGNALED(wstatus)) << "child exit " << WEXITSTATUS(wstatus);
  auto reader = Reader::Open(path);
  ASSERT_TRUE(reader.ok()) << reader.status().ToString();
  EXPECT_TRUE(reader->recovery().truncated);
  auto messages = ReadAll(*reader);
  ASSERT_EQ(messages.size(), kFlushed);
  for (std::uint32_t i = 0; i < kFlushed; ++i) ASSERT_EQ(messages[i].sequence, i);
}

}  // namespace
}  // namespace dyad::mcap
