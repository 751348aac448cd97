// DecodeRow does not allocate once the row's strings have grown (bag export's per-message path).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <vector>

#include "dyad/cdr_decoder.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

// Counting replacements of the global allocation functions, for this test binary only.
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace dyad::cdr {
namespace {

TEST(CdrCsv, DecodeRowReusesTheRowWithoutAllocating) {
  const StatusOr<Schema> parsed = Schema::Parse(
      "module m { struct Inner { double a; long b; };\n"
      "struct Sample { string name_longer_than_sso; sequence<Inner> items; double x; }; };\n");
  ASSERT_TRUE(parsed.ok()) << parsed.status().ToString();
  const Schema& schema = *parsed;
  // Little-endian plain CDR: "a long enough name\0", 2 items, x.
  std::vector<std::uint8_t> bytes = {0x00, 0x01, 0x00, 0x00};
  auto put = [&](const void* p, std::size_t n) {
    while ((bytes.size() - 4) % n != 0 && n <= 8) bytes.push_back(0);  // Align to the value's size.
    bytes.insert(bytes.end(), static_cast<const std::uint8_t*>(p), static_cast<const std::uint8_t*>(p) + n);
  };
  const char name[] = "a long enough name";
  const std::uint32_t length = sizeof(name), count = 2;
  put(&length, 4);
  bytes.insert(bytes.end(), name, name + sizeof(name));
  put(&count, 4);
  for (std::int32_t i = 0; i < 2; ++i) {
    const double a = 0.25 + i;
    put(&a, 8);
    put(&i, 4);
  }
  const double x = -1.5;
  put(&x, 8);

  std::vector<std::string> row;
  ASSERT_TRUE(DecodeRow(schema, "m::Sample", bytes.data(), bytes.size(), &row).ok());
  EXPECT_EQ(row, (std::vector<std::string>{"a long enough name", "[{\"a\":0.25,\"b\":0},{\"a\":1.25,\"b\":1}]", "-1.5"}));
  const std::string type = "m::Sample";
  const long before = g_allocations.load();
  for (int i = 0; i < 100; ++i) ASSERT_TRUE(DecodeRow(schema, type, bytes.data(), bytes.size(), &row).ok());
  EXPECT_EQ(g_allocations.load() - before, 0);
}

}  // namespace
}  // namespace dyad::cdr
