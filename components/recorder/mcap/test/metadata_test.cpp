// Metadata records (the graph YAML) come back byte for byte, through the summary or a scan.
#include <gtest/gtest.h>

#include "test_files.hpp"

namespace dyad::mcap {
namespace {

const char* const kGraphYaml =
    "nodes:\n"
    "  - id: mixer\n"
    "    type: compliance_mixer\n"
    "    params: {g: 0.9, saturation: 5}\n"
    "# unicode: \xc3\xa9t\xc3\xa9, quotes: \"x\" 'y', tab:\t.\n";

TEST(Metadata, RoundTripsThroughTheSummaryAndTheScan) {
  const std::string path = testing::TempPath("m.mcap");
  {
    auto writer = Writer::Open(path);
    ASSERT_TRUE(writer.ok());
    ASSERT_TRUE(writer->AddMetadata("dyad.graph", {{"yaml", kGraphYaml}, {"file", "demo.yaml"}}).ok());
    auto channel = writer->AddChannel("/x", "cdr", 0);
    ASSERT_TRUE(writer->Write(*channel, 0, 1, 1, testing::Payload(0, 16)).ok());
    ASSERT_TRUE(writer->AddMetadata("dyad.run", {{"outcome", "ok"}}).ok());
    ASSERT_TRUE(writer->AddMetadata("empty", {}).ok());
    ASSERT_TRUE(writer->Close().ok());
  }
  for (bool use_summary : {true, false}) {
    ReaderOptions options;
    options.use_summary = use_summary;
    auto reader = Reader::Open(path, options);
    ASSERT_TRUE(reader.ok());
    EXPECT_EQ(reader->recovery().used_summary, use_summary);
    const auto& metadata = reader->metadata();
    ASSERT_EQ(metadata.size(), 3u);
    EXPECT_EQ(metadata[0].name, "dyad.graph");
    EXPECT_EQ(metadata[0].entries.at("yaml"), kGraphYaml);
    EXPECT_EQ(metadata[0].entries.at("file"), "demo.yaml");
    EXPECT_EQ(metadata[1].name, "dyad.run");
    EXPECT_EQ(metadata[1].entries.at("outcome"), "ok");
    EXPECT_TRUE(metadata[2].entries.empty());
    EXPECT_EQ(reader->statistics().metadata_count, 3u);
  }
}

}  // namespace
}  // namespace dyad::mcap
