// RecordQueue: the recorder's hand-over queue.
#include <gtest/gtest.h>

#include <thread>

#include "record_queue.hpp"

namespace dyad::recorder {
namespace {

std::vector<uint8_t> Bytes(uint64_t v, size_t n) {
  std::vector<uint8_t> b(n, static_cast<uint8_t>(v));
  return b;
}

TEST(RecordQueue, EveryRecordOfSeveralProducersArrivesInOrderPerProducer) {
  RecordQueue q(8 * 1024);  // small: producers must wait for the consumer often
  constexpr int kProducers = 3, kEach = 20000;
  std::vector<std::thread> producers;
  for (int p = 0; p < kProducers; ++p)
    producers.emplace_back([&, p] {
      for (int i = 1; i <= kEach; ++i) {
        RecordEntry e;
        e.channel = static_cast<uint16_t>(p + 1);
        e.sequence = static_cast<uint32_t>(i);
        e.log_time = static_cast<uint64_t>(i) * 10;
        auto b = Bytes(static_cast<uint64_t>(i), static_cast<size_t>(i % 40));
        ASSERT_TRUE(q.Push(e, b));
      }
    });
  std::vector<uint32_t> last(kProducers + 1, 0);
  uint64_t total = 0;
  std::thread consumer([&] {
    RecordBatch batch;
    while (q.TakeBatch(&batch, 10)) {
      batch.ForEach([&](const RecordEntry& e, std::span<const uint8_t> data) {
        EXPECT_EQ(e.sequence, last[e.channel] + 1);
        last[e.channel] = e.sequence;
        EXPECT_EQ(data.size(), e.sequence % 40u);
        for (uint8_t x : data) EXPECT_EQ(x, static_cast<uint8_t>(e.sequence));
        EXPECT_EQ(e.log_time, uint64_t{e.sequence} * 10);
        ++total;
      });
    }
  });
  for (auto& t : producers) t.join();
  q.Close();
  consumer.join();
  EXPECT_EQ(total, uint64_t{kProducers} * kEach);
  for (int p = 1; p <= kProducers; ++p) EXPECT_EQ(last[p], static_cast<uint32_t>(kEach));
  EXPECT_GT(q.producer_waits(), 0u) << "the test meant to exercise back-pressure";
  EXPECT_LE(q.high_water_bytes(), 4u * 1024u);
}

TEST(RecordQueue, CloseHandsOverWhatIsLeftThenEnds) {
  RecordQueue q(4096);
  RecordEntry e;
  e.channel = 1;
  ASSERT_TRUE(q.Push(e, Bytes(1, 3)));
  q.Close();
  EXPECT_FALSE(q.Push(e, Bytes(1, 3)));
  RecordBatch b;
  ASSERT_TRUE(q.TakeBatch(&b, 0));
  EXPECT_EQ(b.count(), 1u);
  EXPECT_FALSE(q.TakeBatch(&b, 0));
}

TEST(RecordQueue, ARecordLargerThanAnArenaIsAcceptedWhole) {
  RecordQueue q(4096);
  RecordEntry e;
  ASSERT_TRUE(q.Push(e, Bytes(7, 100000)));
  RecordBatch b;
  ASSERT_TRUE(q.TakeBatch(&b, 0));
  size_t seen = 0;
  b.ForEach([&](const RecordEntry&, std::span<const uint8_t> d) { seen = d.size(); });
  EXPECT_EQ(seen, 100000u);
}

}  // namespace
}  // namespace dyad::recorder
