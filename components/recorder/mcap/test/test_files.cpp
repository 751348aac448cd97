#include "test_files.hpp"

#include <gtest/gtest.h>

#include <fstream>

namespace dyad::mcap::testing {

const char* const kPoseIdl =
    "module dyad { module msg {\n"
    "  struct Pose2 { unsigned long long stamp_ns; double x; double y; double theta; };\n"
    "}; };\n";

std::string TempPath(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string path = ::testing::TempDir() + "dyad_mcap_" + info->test_suite_name() + "_" + info->name() + "_" + name;
  std::remove(path.c_str());
  return path;
}

std::vector<std::uint8_t> Payload(std::uint32_t i, std::size_t size) {
  std::vector<std::uint8_t> data(size);
  const std::uint8_t cdr_header[4] = {0x00, 0x01, 0x00, 0x00};  // CDR little-endian.
  for (std::size_t k = 0; k < size; ++k) {
    data[k] = k < 4 ? cdr_header[k] : static_cast<std::uint8_t>((i * 31 + k * 7) ^ (i >> 3));
  }
  return data;
}

WrittenFile WriteChunkedFile(const std::string& path, const WriterOptions& options, int chunks,
                             int per_chunk) {
  WrittenFile file{path, {}};
  auto writer = Writer::Open(path, options);
  EXPECT_TRUE(writer.ok()) << writer.status().ToString();
  if (!writer.ok()) return file;
  auto schema = writer->AddSchema("dyad::msg::Pose2", "omgidl", kPoseIdl);
  EXPECT_TRUE(schema.ok());
  const char* topics[] = {"/a", "/b", "/c"};
  ChannelId ids[3] = {};
  for (int c = 0; c < 3; ++c) {
    auto id = writer->AddChannel(topics[c], "cdr", *schema, {{"qos", "reliable"}});
    EXPECT_TRUE(id.ok());
    ids[c] = *id;
  }
  EXPECT_TRUE(writer->AddMetadata("dyad.graph", {{"yaml", "nodes:\n  - id: recorder\n"}}).ok());
  std::uint32_t i = 0;
  for (int k = 0; k < chunks; ++k) {
    for (int m = 0; m < per_chunk; ++m, ++i) {
      TestMessage msg{topics[i % 3], i / 3, 1'000'000'000ull + i * 1'000'000ull,
                      999'000'000ull + i * 1'000'000ull, Payload(i, 48)};
      EXPECT_TRUE(writer->Write(ids[i % 3], msg.sequence, msg.log_time, msg.publish_time, msg.data).ok());
      file.messages.push_back(std::move(msg));
    }
    EXPECT_TRUE(writer->Flush().ok());
  }
  Status closed = writer->Close();
  EXPECT_TRUE(closed.ok()) << closed.ToString();
  return file;
}

std::vector<TestMessage> ReadAll(const Reader& reader, const ReadOptions& options, Status* status) {
  std::vector<TestMessage> out;
  Status s = reader.ReadMessages(options, [&](const MessageView& m) {
    out.push_back({m.channel->topic, m.sequence, m.log_time, m.publish_time,
                   std::vector<std::uint8_t>(m.data.begin(), m.data.end())});
    return true;
  });
  if (status) *status = s;
  return out;
}

std::vector<ChunkInfo> Chunks(const std::string& path) {
  auto reader = Reader::Open(path);
  EXPECT_TRUE(reader.ok()) << reader.status().ToString();
  return reader.ok() ? reader->chunks() : std::vector<ChunkInfo>{};
}

namespace {

// Replaces bytes of a file in place (the host is little-endian, as dyad_mcap requires).
void Overwrite(const std::string& path, std::uint64_t offset, const void* bytes, std::size_t size) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(static_cast<std::streamoff>(offset));
  f.write(static_cast<const char*>(bytes), static_cast<std::streamsize>(size));
  EXPECT_TRUE(f.good()) << path << " at " << offset;
}

}  // namespace

void FlipByte(const std::string& path, std::uint64_t offset) {
  char c = 0;
  {
    std::ifstream f(path, std::ios::binary);
    f.seekg(static_cast<std::streamoff>(offset));
    f.read(&c, 1);
  }
  c = static_cast<char>(c ^ 0xFF);
  Overwrite(path, offset, &c, 1);
}

void OverwriteU32(const std::string& path, std::uint64_t offset, std::uint32_t value) {
  Overwrite(path, offset, &value, sizeof(value));
}

void OverwriteU64(const std::string& path, std::uint64_t offset, std::uint64_t value) {
  Overwrite(path, offset, &value, sizeof(value));
}

}  // namespace dyad::mcap::testing
