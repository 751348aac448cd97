// Writer::Write does not allocate in steady state (the recorder's hot path).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "test_files.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

// Counting replacements of the global allocation functions (all malloc-backed so every delete
// matches), for this test binary only.
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size == 0 ? 1 : size);
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept { return operator new(size, tag); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

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
  const long before = g_allocations.load();
  ASSERT_TRUE(write(100));   // Within one chunk: nothing at all.
  EXPECT_EQ(g_allocations.load() - before, 0);
  const long before_chunks = g_allocations.load();
  ASSERT_TRUE(write(20000));  // ~100 chunks: only the per-chunk index entry may allocate.
  EXPECT_LE(g_allocations.load() - before_chunks, 2 * 100 + 10);
  ASSERT_TRUE(writer->Close().ok());
}

}  // namespace
}  // namespace dyad::mcap
