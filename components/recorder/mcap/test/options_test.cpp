// WriterOptions: defaults are valid; each broken constraint is named with its value.
#include <gtest/gtest.h>

#include "dyad/mcap/writer.hpp"

namespace dyad::mcap {
namespace {

TEST(WriterOptions, DefaultsAreValid) { EXPECT_TRUE(WriterOptions().Validate().ok()); }

TEST(WriterOptions, TinyChunkSizeIsRejectedWithItsValue) {
  WriterOptions options;
  options.chunk_size = 100;
  Status s = options.Validate();
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
  EXPECT_EQ(s.message(), "WriterOptions: chunk_size = 100: must be between 1024 and 1073741824 bytes");
}

TEST(WriterOptions, ZstdLevelOutOfRangeIsRejected) {
  WriterOptions options;
  options.zstd_level = 25;
  EXPECT_EQ(options.Validate().message(), "WriterOptions: zstd_level = 25: must be 1..19");
  options.compression = Compression::kNone;
  EXPECT_TRUE(options.Validate().ok());  // The level is unused without compression.
}

TEST(WriterOptions, OpenRefusesInvalidOptionsNamingTheFile) {
  WriterOptions options;
  options.chunk_size = 0;
  auto writer = Writer::Open(::testing::TempDir() + "never.mcap", options);
  ASSERT_FALSE(writer.ok());
  EXPECT_EQ(writer.status().message().rfind(::testing::TempDir() + "never.mcap: WriterOptions: chunk_size = 0", 0), 0u)
      << writer.status().message();
}

}  // namespace
}  // namespace dyad::mcap
