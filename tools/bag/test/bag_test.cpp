// `dyad bag info` and `dyad bag export`: reports, CSV contents, decoders and exit codes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "bag_commands.hpp"
#include "bag_info.hpp"
#include "csv_export.hpp"
#include "dyad/mcap/writer.hpp"

namespace dyad::bag {
namespace {

std::string TempPath(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string path = ::testing::TempDir() + "dyad_bag_" + info->name() + "_" + name;
  std::filesystem::remove_all(path);
  return path;
}

// Two channels (/robot/pose x 4, /human/pose x 2), one Flush() per 3 messages, a graph YAML.
std::string WriteSample(const std::string& path) {
  mcap::WriterOptions options;
  options.chunk_size = 1 << 20;
  auto writer = mcap::Writer::Open(path, options);
  EXPECT_TRUE(writer.ok());
  auto schema = writer->AddSchema("dyad::msg::Pose2", "omgidl", "struct Pose2 { double x; };");
  auto robot = writer->AddChannel("/robot/pose", "cdr", *schema);
  auto human = writer->AddChannel("/human/pose", "cdr", *schema);
  EXPECT_TRUE(writer->AddMetadata("dyad.graph", {{"yaml", "nodes: []\n"}}).ok());
  for (std::uint32_t i = 0; i < 6; ++i) {
    const std::uint8_t payload[3] = {0x00, static_cast<std::uint8_t>(i), 0xAB};
    const bool is_robot = i % 3 != 2;
    EXPECT_TRUE(writer->Write(is_robot ? *robot : *human, i, 1'000'000'000ull * (i + 1), 1000 + i, payload).ok());
    if (i % 3 == 2) {
      EXPECT_TRUE(writer->Flush().ok());
    }
  }
  EXPECT_TRUE(writer->Close().ok());
  return path;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

int RunCli(std::vector<std::string> args) {
  CLI::App app{"dyad"};
  int exit_code = -1;
  dyad::cli::AddBagCommands(app, exit_code);
  args.insert(args.begin(), "dyad");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  app.parse(static_cast<int>(argv.size()), argv.data());
  return exit_code;
}

TEST(BagInfo, ListsChannelsCountsChunksAndMetadata) {
  auto reader = mcap::Reader::Open(WriteSample(TempPath("a.mcap")));
  ASSERT_TRUE(reader.ok());
  const std::string text = FormatInfo(*reader);
  EXPECT_NE(text.find("state:       complete (summary section used)"), std::string::npos) << text;
  EXPECT_NE(text.find("messages:    6\n"), std::string::npos) << text;
  EXPECT_NE(text.find("  1  /robot/pose  4 msgs  [cdr, dyad::msg::Pose2]"), std::string::npos) << text;
  EXPECT_NE(text.find("  2  /human/pose  2 msgs  [cdr, dyad::msg::Pose2]"), std::string::npos) << text;
  EXPECT_NE(text.find("chunks:      2 (zstd: 2)"), std::string::npos) << text;
  EXPECT_NE(text.find("  dyad.graph: yaml (10 bytes)"), std::string::npos) << text;
  EXPECT_NE(text.find("start:       1.000000000 (1970-01-01T00:00:01Z)"), std::string::npos) << text;
  EXPECT_NE(text.find("duration:    5.000 s"), std::string::npos) << text;
}

TEST(BagInfo, SaysATruncatedFileWasCutShortAndWhereItRecoveredTo) {
  const std::string path = WriteSample(TempPath("a.mcap"));
  std::uint64_t second_chunk = 0;
  {
    auto reader = mcap::Reader::Open(path);
    second_chunk = reader->chunks()[1].offset;
  }
  ASSERT_EQ(::truncate(path.c_str(), static_cast<off_t>(second_chunk + 10)), 0);
  auto reader = mcap::Reader::Open(path);
  ASSERT_TRUE(reader.ok());
  const std::string text = FormatInfo(*reader);
  EXPECT_NE(text.find("cut short"), std::string::npos) << text;
  EXPECT_NE(text.find("recovered up to byte " + std::to_string(second_chunk)), std::string::npos) << text;
  EXPECT_NE(text.find("messages:    3\n"), std::string::npos) << text;
}

TEST(CsvExport, WritesOneHexCsvPerChannelInLogTimeOrder) {
  auto reader = mcap::Reader::Open(WriteSample(TempPath("a.mcap")));
  ASSERT_TRUE(reader.ok());
  const std::string dir = TempPath("out");
  CsvExportSummary summary;
  ASSERT_TRUE(ExportCsv(*reader, dir, {}, &summary).ok());
  EXPECT_EQ(summary.files.at("/robot/pose"), dir + "/robot_pose.csv");
  EXPECT_EQ(ReadText(dir + "/robot_pose.csv"),
            "log_time,publish_time,sequence,data_hex\n"
            "1000000000,1000,0,0000ab\n"
            "2000000000,1001,1,0001ab\n"
            "4000000000,1003,3,0003ab\n"
            "5000000000,1004,4,0004ab\n");
  EXPECT_EQ(ReadText(dir + "/human_pose.csv"),
            "log_time,publish_time,sequence,data_hex\n"
            "3000000000,1002,2,0002ab\n"
            "6000000000,1005,5,0005ab\n");
  EXPECT_EQ(summary.rows.at("/human/pose"), 2u);
}

TEST(CsvExport, UsesTheDecoderTheFactoryPicksPerSchema) {
  auto reader = mcap::Reader::Open(WriteSample(TempPath("a.mcap")));
  ASSERT_TRUE(reader.ok());
  CsvExportOptions options;
  options.topics = {"/robot/pose"};
  options.decoder_factory = [](const mcap::Schema* schema, const mcap::Channel&) -> std::optional<PayloadDecoder> {
    if (schema == nullptr || schema->name != "dyad::msg::Pose2") return std::nullopt;
    return PayloadDecoder{{"index", "note"},
                          [](std::span<const std::uint8_t> data, std::vector<std::string>* cells, std::string* error) {
                            if (data[1] == 3) {
                              *error = "index 3 is cursed";
                              return false;
                            }
                            cells->push_back(std::to_string(data[1]));
                            cells->push_back("a,\"b\"");
                            return true;
                          }};
  };
  const std::string dir = TempPath("out");
  CsvExportSummary summary;
  ASSERT_TRUE(ExportCsv(*reader, dir, options, &summary).ok());
  EXPECT_FALSE(std::filesystem::exists(dir + "/human_pose.csv"));
  EXPECT_EQ(ReadText(dir + "/robot_pose.csv"),
            "log_time,publish_time,sequence,index,note\n"
            "1000000000,1000,0,0,\"a,\"\"b\"\"\"\n"
            "2000000000,1001,1,1,\"a,\"\"b\"\"\"\n"
            "4000000000,1003,3,,\n"
            "5000000000,1004,4,4,\"a,\"\"b\"\"\"\n");
  EXPECT_EQ(summary.undecodable, 1u);
  EXPECT_EQ(summary.first_decode_error, "/robot/pose seq 3: index 3 is cursed");
}

TEST(CsvExport, TopicNamesBecomeSafeFileNames) {
  EXPECT_EQ(FileNameForTopic("/robot/pose"), "robot_pose");
  EXPECT_EQ(FileNameForTopic("/a b/c:d"), "a_b_c_d");
  EXPECT_EQ(FileNameForTopic("/"), "topic");
}

TEST(BagCommands, ExitCodesSayOkFailureOrBadInput) {
  const std::string path = WriteSample(TempPath("a.mcap"));
  EXPECT_EQ(RunCli({"bag", "info", path}), 0);
  EXPECT_EQ(RunCli({"bag", "info", "--scan", path}), 0);
  EXPECT_EQ(RunCli({"bag", "info", TempPath("missing.mcap")}), 2);
  EXPECT_EQ(RunCli({"bag", "export", path, "--csv", TempPath("out")}), 0);
  EXPECT_EQ(RunCli({"bag", "export", path, "--csv", TempPath("out2"), "--topic", "/nope"}), 2);
  // A directory that cannot be created: its parent is a regular file.
  EXPECT_EQ(RunCli({"bag", "export", path, "--csv", path + "/sub"}), 1);
}

}  // namespace
}  // namespace dyad::bag
