// `dyad bag info`, `dyad bag export` and `dyad bag filter`: reports, CSV contents, decoders, errors and exit codes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>

#include <fastdds/rtps/common/SerializedPayload.h>

#include <dyad/msg/types.hpp>
#include <dyad/msg/types_support.hpp>

#include "bag_commands.hpp"
#include "dyad/testing/cli.hpp"
#include "bag_info.hpp"
#include "csv_export.hpp"
#include "losses.hpp"
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
// The payloads are 3 opaque bytes, not CDR: for the data_hex path (ExportCsv without a decoder).
std::string WriteSample(const std::string& path, const std::string& graph_yaml = "nodes: []\n") {
  mcap::WriterOptions options;
  options.chunk_size = 1 << 20;
  auto writer = mcap::Writer::Open(path, options);
  EXPECT_TRUE(writer.ok());
  auto schema = writer->AddSchema("dyad::msg::Pose2", "omgidl",
                                  "module dyad { module msg { struct Pose2 { double x; }; }; };");
  auto robot = writer->AddChannel("/robot/pose", "cdr", *schema);
  auto human = writer->AddChannel("/human/pose", "cdr", *schema);
  EXPECT_TRUE(writer->AddMetadata("dyad.graph", {{"yaml", graph_yaml}}).ok());
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

// Runs `dyad ARGS...` and returns its exit code; *err (if given) receives what it wrote to stderr.
int RunCli(std::vector<std::string> args, std::string* err = nullptr) {
  const auto r = dyad::testing::RunCommand(dyad::cli::AddBagCommands, std::move(args));
  if (err) *err = r.err;
  return r.code;
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

// A stepped run's stamps are simulated time since its start, not dates (they read as 1970).
TEST(BagInfo, SteppedRecordingsShowSimulatedTimeNotDates) {
  auto reader = mcap::Reader::Open(WriteSample(TempPath("s.mcap"), "graph: g\nclock: stepped\n"));
  ASSERT_TRUE(reader.ok());
  const std::string text = FormatInfo(*reader);
  EXPECT_NE(text.find("start:       1.000000000 (simulated time since start: stepped clock)"), std::string::npos) << text;
  EXPECT_EQ(text.find("1970"), std::string::npos) << text;
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
                          [](std::span<const std::uint8_t> data, std::vector<std::string>* cells) {
                            if (data[1] == 3) return Status::DataLoss("index 3 is cursed");
                            *cells = {std::to_string(data[1]), "a,\"b\""};
                            return Status::OK();
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

// A recording of dyad::msg::Counter as the recorder writes it: the type's IDL text as an omgidl
// schema, samples serialized by the generated PubSubType (real CDR). `idl` replaces the schema
// text; `garble` cuts the payload of the message with that sequence number short.
std::string WriteCounters(const std::string& path, const std::string& idl = MessageTraits<msg::Counter>::kIdl,
                          std::uint32_t garble = UINT32_MAX) {
  auto writer = mcap::Writer::Open(path);
  EXPECT_TRUE(writer.ok()) << writer.status().ToString();
  auto schema = writer->AddSchema(MessageTraits<msg::Counter>::kName, "omgidl", idl);
  auto channel = writer->AddChannel("/counter", "cdr", *schema);
  MessageTraits<msg::Counter>::PubSubType type;
  for (std::uint32_t i = 0; i < 3; ++i) {
    msg::Counter m;
    m.header().source(i == 1 ? "say \"hi\", twice" : "counter");
    m.header().sequence_number(i + 1);
    m.header().stamp_ns(-5 + static_cast<std::int64_t>(i));
    m.value(std::int64_t{1} << (40 + i));
    eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&m)());
    EXPECT_TRUE(type.serialize(&m, &payload));
    const std::uint32_t size = i == garble ? payload.length - 3 : payload.length;
    EXPECT_TRUE(writer->Write(*channel, i, 1000 * (i + 1), 900 * (i + 1), {payload.data, size}).ok());
  }
  EXPECT_TRUE(writer->Close().ok());
  return path;
}

TEST(BagCommands, ExitCodesSayOkFailureOrBadInput) {
  const std::string path = WriteCounters(TempPath("a.mcap"));
  std::string err;
  EXPECT_EQ(RunCli({"bag", "info", path}), 0);
  EXPECT_EQ(RunCli({"bag", "info", "--scan", path}), 0);
  EXPECT_EQ(RunCli({"bag", "export", path, "--csv", TempPath("out")}, &err), 0) << err;

  EXPECT_EQ(RunCli({"bag", "info", TempPath("missing.mcap")}, &err), 2);
  EXPECT_EQ(err.rfind("dyad bag: " + TempPath("missing.mcap") + ": open for reading: ", 0), 0u) << err;
  EXPECT_EQ(RunCli({"bag", "info", ::testing::TempDir()}, &err), 2);
  EXPECT_EQ(err, "dyad bag: " + ::testing::TempDir() + ": not a regular file\n");
  const std::string text = TempPath("text.mcap");
  std::ofstream(text) << "not a recording\n";
  EXPECT_EQ(RunCli({"bag", "export", text, "--csv", TempPath("out3")}, &err), 2);
  EXPECT_EQ(err, "dyad bag: " + text + ": not an MCAP file (wrong magic bytes)\n");
  EXPECT_EQ(RunCli({"bag", "export", path, "--csv", TempPath("out2"), "--topic", "/nope"}, &err), 2);
  EXPECT_EQ(err, "dyad bag: " + path + ": no channel with topic \"/nope\"\n");
  // A directory that cannot be created: its parent is a regular file.
  EXPECT_EQ(RunCli({"bag", "export", path, "--csv", path + "/sub"}, &err), 1);
  EXPECT_EQ(err.rfind("dyad bag: " + path + "/sub: cannot create directory: ", 0), 0u) << err;
}

TEST(BagCommands, ExportOfADamagedRecordingSkipsTheChunkAndFails) {
  const std::string path = WriteCounters(TempPath("a.mcap"));
  std::uint64_t chunk = 0;
  {
    auto reader = mcap::Reader::Open(path);
    ASSERT_TRUE(reader.ok());
    ASSERT_EQ(reader->chunks().size(), 1u);
    chunk = reader->chunks()[0].offset;
  }
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(chunk + 1 + 8 + 8 + 8 + 8));  // Its CRC field.
    f.write("\xde\xad", 2);
  }
  std::string err;
  const std::string dir = TempPath("out");
  EXPECT_EQ(RunCli({"bag", "export", path, "--csv", dir}, &err), 1);
  EXPECT_EQ(err, "dyad bag: " + path + ": skipped 1 damaged chunk(s); `dyad bag info --scan " + path +
                     "` lists them\n");
  EXPECT_EQ(ReadText(dir + "/counter.csv"),
            "log_time,publish_time,sequence,header.source,header.sequence_number,header.stamp_ns,value\n");
  const auto info = dyad::testing::RunCommand(dyad::cli::AddBagCommands, {"bag", "info", "--scan", path});
  EXPECT_EQ(info.code, 1);
  const std::string& report = info.out;
  EXPECT_NE(report.find("damaged:     1 chunk(s)\n  at offset " + std::to_string(chunk) + ": CRC mismatch"),
            std::string::npos)
      << report;
}

TEST(BagCommands, ExportDecodesOmgidlCdrIntoOneColumnPerField) {
  const std::string path = WriteCounters(TempPath("counter.mcap"));
  const std::string dir = TempPath("out");
  std::string err;
  EXPECT_EQ(RunCli({"bag", "export", path, "--csv", dir}, &err), 0) << err;
  EXPECT_EQ(err, "");
  EXPECT_EQ(ReadText(dir + "/counter.csv"),
            "log_time,publish_time,sequence,header.source,header.sequence_number,header.stamp_ns,value\n"
            "1000,900,0,counter,1,-5,1099511627776\n"
            "2000,1800,1,\"say \"\"hi\"\", twice\",2,-4,2199023255552\n"
            "3000,2700,2,counter,3,-3,4398046511104\n");
}

TEST(BagCommands, ExportLeavesUndecodablePayloadsEmptyAndFails) {
  const std::string path = WriteCounters(TempPath("counter.mcap"), MessageTraits<msg::Counter>::kIdl, 2);
  const std::string dir = TempPath("out");
  std::string err;
  EXPECT_EQ(RunCli({"bag", "export", path, "--csv", dir}, &err), 1);
  EXPECT_NE(err.find("dyad bag: " + path + ": 1 payload(s) could not be decoded (their cells are left empty); "
                     "first: /counter seq 2: offset 32 (value): truncated: long long needs 8 bytes, 5 left"),
            std::string::npos)
      << err;
  EXPECT_NE(ReadText(dir + "/counter.csv").find("\n3000,2700,2,,,,\n"), std::string::npos);
}

TEST(BagCommands, ExportNamesAnOmgidlSchemaThatDoesNotParseAndFallsBackToHex) {
  const std::string path =
      WriteCounters(TempPath("counter.mcap"), "module dyad { module msg {\nstruct Counter { union u; };\n}; };\n");
  const std::string dir = TempPath("out");
  std::string err;
  EXPECT_EQ(RunCli({"bag", "export", path, "--csv", dir}, &err), 1);
  EXPECT_EQ(err, "dyad bag: " + path +
                     ": /counter: schema 1 \"dyad::msg::Counter\" (omgidl): line 2: 'union' is not supported; "
                     "exported as data_hex\n");
  EXPECT_EQ(ReadText(dir + "/counter.csv").rfind("log_time,publish_time,sequence,data_hex\n", 0), 0u);
}

TEST(BagCommands, ExportNamesAnOmgidlSchemaWithoutItsType) {
  const std::string path = WriteCounters(TempPath("counter.mcap"), "struct Other { long x; };\n");
  std::string err;
  EXPECT_EQ(RunCli({"bag", "export", path, "--csv", TempPath("out")}, &err), 1);
  EXPECT_EQ(err, "dyad bag: " + path +
                     ": /counter: schema 1 \"dyad::msg::Counter\" (omgidl): its IDL defines no struct "
                     "\"dyad::msg::Counter\"; exported as data_hex\n");
}

// Two writers on one channel: "a" loses 4..6 and falls silent 5 s before the end; "b" is complete.
TEST(BagLosses, SaysPerWriterWhatWasLostAndWhen) {
  const std::string path = TempPath("losses.mcap");
  {
    auto writer = mcap::Writer::Open(path);
    ASSERT_TRUE(writer.ok());
    auto schema = writer->AddSchema(MessageTraits<msg::Counter>::kName, "omgidl", MessageTraits<msg::Counter>::kIdl);
    auto channel = writer->AddChannel("c", "cdr", *schema);
    MessageTraits<msg::Counter>::PubSubType type;
    std::uint32_t n = 0;
    auto put = [&](const std::string& source, std::uint64_t seq, std::int64_t stamp_ms) {
      msg::Counter m;
      m.header().source(source);
      m.header().sequence_number(seq);
      m.header().stamp_ns(stamp_ms * 1'000'000);
      eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&m)());
      ASSERT_TRUE(type.serialize(&m, &payload));
      ASSERT_TRUE(writer->Write(*channel, n++, stamp_ms, stamp_ms, {payload.data, payload.length}).ok());
    };
    for (std::uint64_t i = 1; i <= 100; ++i) {
      if ((i < 4 || i > 6) && i <= 50) put("a", i, 100 * static_cast<std::int64_t>(i));  // 10 Hz, stops at 5 s
      put("b", i, 100 * static_cast<std::int64_t>(i));
    }
    ASSERT_TRUE(writer->Close().ok());
  }
  auto reader = mcap::Reader::Open(path);
  ASSERT_TRUE(reader.ok());
  auto losses = FindLosses(*reader);
  ASSERT_TRUE(losses.ok()) << losses.status().message();
  ASSERT_EQ(losses->writers.size(), 2u);
  const WriterLosses& a = losses->writers[0];
  EXPECT_EQ(a.writer, "a");
  EXPECT_EQ(a.samples, 47u);
  ASSERT_EQ(a.gaps.size(), 1u);
  EXPECT_EQ(a.gaps[0].missing, 3u);
  EXPECT_EQ(a.gaps[0].from_ns, 300'000'000);
  EXPECT_EQ(a.gaps[0].to_ns, 700'000'000);
  EXPECT_NEAR(a.silent_at_end_s, 5.0, 1e-9);
  const WriterLosses& b = losses->writers[1];
  EXPECT_TRUE(b.gaps.empty());
  EXPECT_EQ(b.silent_at_end_s, 0);
  const std::string text = FormatLosses(*losses);
  EXPECT_NE(text.find("  c  a  47 samples, 1..50: 3 missing\n    3 lost from +0.2 s to +0.6 s\n"
                      "    silent for the last 5.0 s of the recording\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("  c  b "), std::string::npos) << "a complete writer is not listed\n" << text;
}

// A driver's stopped states (#40: a lost arm must not be silent): each run of stopped samples with
// its start and length, and one still under way at the end. Before, bag info said nothing of them.
TEST(BagLosses, SaysWhenAndHowLongTheArmWasStopped) {
  const std::string path = TempPath("arm.mcap");
  {
    auto writer = mcap::Writer::Open(path);
    ASSERT_TRUE(writer.ok());
    auto schema = writer->AddSchema(MessageTraits<msg::CartesianState>::kName, "omgidl",
                                    MessageTraits<msg::CartesianState>::kIdl);
    auto channel = writer->AddChannel("robot/state", "cdr", *schema);
    MessageTraits<msg::CartesianState>::PubSubType type;
    for (std::uint32_t i = 0; i < 40; ++i) {  // 10 Hz from 0 s; stopped at 1.0..1.9 s and from 3.5 s
      msg::CartesianState m;
      m.header().source("arm");
      m.header().sequence_number(i + 1);
      m.header().stamp_ns(static_cast<std::int64_t>(i) * 100'000'000);
      m.stopped((i >= 10 && i < 20) || i >= 35);
      eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&m)());
      ASSERT_TRUE(type.serialize(&m, &payload));
      ASSERT_TRUE(writer->Write(*channel, i, i * 100'000'000ull, i * 100'000'000ull, {payload.data, payload.length}).ok());
    }
    ASSERT_TRUE(writer->Close().ok());
  }
  auto reader = mcap::Reader::Open(path);
  ASSERT_TRUE(reader.ok());
  auto losses = FindLosses(*reader);
  ASSERT_TRUE(losses.ok()) << losses.status().message();
  ASSERT_EQ(losses->arms.size(), 1u);
  ASSERT_EQ(losses->arms[0].stops.size(), 2u);
  EXPECT_EQ(losses->arms[0].stops[0].from_ns, 1'000'000'000);
  EXPECT_EQ(losses->arms[0].stops[0].to_ns, 2'000'000'000);
  EXPECT_TRUE(losses->arms[0].stops[1].until_end);
  const std::string text = FormatLosses(*losses);
  EXPECT_NE(text.find("arm:         robot/state: stopped 2 times, 1.4 s (the driver could not move the arm; the mixer "
                      "holds meanwhile)\n  +1.0 s  for 1.0 s\n  +3.5 s  for 0.4 s, still stopped at the end\n"),
            std::string::npos)
      << text;
}

// `dyad bag filter`: read back by the reader (an independent path from the writer's buffers):
// the chosen topic and window, every field of each message kept, the graph's metadata and a note.
TEST(BagFilter, KeepsTheChosenTopicsAndWindowExactly) {
  const std::string in = WriteSample(TempPath("in.mcap"), "graph: g\n");
  const std::string out = TempPath("out.mcap");
  std::string err;
  // Messages at 1..6 s (robot at 1, 2, 4, 5 s); from 1 s to 2.5 s after the first: robot at 2 s only.
  ASSERT_EQ(RunCli({"bag", "filter", in, "-o", out, "--topics", "/robot/pose", "--start", "1", "--end", "2.5"}, &err), 0) << err;
  auto r = mcap::Reader::Open(out);
  ASSERT_TRUE(r.ok()) << r.status().message();
  std::vector<std::tuple<std::string, std::uint32_t, std::uint64_t, std::uint64_t, std::vector<std::uint8_t>>> got;
  ASSERT_TRUE(r->ReadMessages({}, [&](const mcap::MessageView& m) {
                  got.emplace_back(m.channel->topic, m.sequence, m.log_time, m.publish_time,
                                   std::vector<std::uint8_t>(m.data.begin(), m.data.end()));
                  return true;
                }).ok());
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0], std::make_tuple(std::string("/robot/pose"), 1u, 2'000'000'000ull, 1001ull, std::vector<std::uint8_t>{0, 1, 0xAB}));
  ASSERT_EQ(r->schemas().size(), 1u);
  EXPECT_EQ(r->schemas().begin()->second.name, "dyad::msg::Pose2");
  EXPECT_EQ(r->schemas().begin()->second.encoding, "omgidl");
  std::map<std::string, std::map<std::string, std::string>> metadata;
  for (const auto& m : r->metadata()) metadata[m.name] = m.entries;
  EXPECT_EQ(metadata["dyad.graph"]["yaml"], "graph: g\n");
  EXPECT_EQ(metadata["dyad.filter"]["topics"], "/robot/pose");
  EXPECT_EQ(metadata["dyad.filter"]["source"], in);
  // Everything: the same six messages.
  ASSERT_EQ(RunCli({"bag", "filter", in, "-o", out}, &err), 0) << err;
  auto all = mcap::Reader::Open(out);
  ASSERT_TRUE(all.ok());
  EXPECT_EQ(all->statistics().message_count, 6u);
}

TEST(BagFilter, RefusesAnUnknownTopicAnInvertedWindowAndItsOwnInput) {
  const std::string in = WriteSample(TempPath("in.mcap"));
  const std::string out = TempPath("out.mcap");
  std::string err;
  EXPECT_EQ(RunCli({"bag", "filter", in, "-o", out, "--topics", "/nope"}, &err), 2);
  EXPECT_NE(err.find("has no topic '/nope' (it has: /human/pose, /robot/pose)"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out + ".tmp"));
  EXPECT_EQ(RunCli({"bag", "filter", in, "-o", out, "--start", "3", "--end", "2"}, &err), 2);
  EXPECT_NE(err.find("--end 2 is before --start 3"), std::string::npos) << err;
  EXPECT_EQ(RunCli({"bag", "filter", in, "-o", in}, &err), 2);
  EXPECT_NE(err.find("the output must be another file"), std::string::npos) << err;
}

}  // namespace
}  // namespace dyad::bag
