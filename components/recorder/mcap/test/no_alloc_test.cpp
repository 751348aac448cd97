// Writer::Write does not allocate in steady state (the recorder's hot path).
#include <gtest/gtest.h>

#include "dyad/testing/allocation_counter.hpp"

#include <cstdlib>

#include "test_files.hpp"


namespace dyad::mcap {
namespace {

TEST(Writer, SteadyStateWritesDoNotAllocate) {
  WriterOptions options;
  options.chunk_size = 16 * 1024;
  auto writer = Writer::Open(testing::TempPath("f.mcap"), options);
  ASSERT_TRUE(writer.ok());
  ChannelId channels[3];
  for (int c = 0; c < 3; ++c) channels[c] = *writer->AddChannel("/t" + std::to_string(c), "cdr", 0);
  const auto payload = testing::Payload(0, 48);
  std::uint32_t i = 0;
  auto write = [&](int n) {
    for (int k = 0; k < n; ++k, ++i) {
      if (!writer->Write(channels[i % 3], i, i, i, payload).ok()) return false;
    }
    return true;
  };
  ASSERT_TRUE(write(5000));  // Warm up: buffers and per-channel indexes reach their size.
  const long before = dyad::testing::AllocationCount();
  ASSERT_TRUE(write(100));   // Within one chunk: nothing at all.
  EXPECT_EQ(dyad::testing::AllocationCount() - before, 0);
  const long before_chunks = dyad::testing::AllocationCount();
  ASSERT_TRUE(write(20000));  // ~100 chunks: only the per-chunk index entry may allocate.
  EXPECT_LE(dyad::testing::AllocationCount() - before_chunks, 2 * 100 + 10);
  ASSERT_TRUE(writer->Close().ok());
}

}  // namespace
}  // namespace dyad::mcap
