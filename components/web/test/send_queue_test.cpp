// SendQueue: bounded, never blocks producers, drops the busiest channel's oldest frames first,
// never drops control frames, keeps data in push order; hands a stream out in batches at most
// once per flush interval, and wakes an idle consumer at once.
#include "send_queue.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <thread>

namespace dyad::web {
namespace {

using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;

std::vector<std::string> Texts(const std::vector<Frame>& frames) {
  std::vector<std::string> out;
  for (const auto& f : frames) out.push_back(f.bytes + (f.tail ? *f.tail : ""));
  return out;
}

TEST(SendQueue, KeepsPushOrderAcrossChannelsAndControlFirst) {
  SendQueue q(1000);
  q.PushData(1, "a1");
  q.PushData(2, "b1");
  q.PushData(1, "a2");
  q.PushControl("{c}");
  std::vector<Frame> batch;
  ASSERT_TRUE(q.PopAll(&batch));
  EXPECT_EQ(Texts(batch), (std::vector<std::string>{"{c}", "a1", "b1", "a2"}));
  EXPECT_EQ(q.queued_bytes(), 0u);
}

// Finish (WebServer::Close): what was queued still goes out, at once (no flush interval), then
// the end; nothing pushed after it is queued.
TEST(SendQueue, FinishHandsOutWhatIsQueuedThenEnds) {
  SendQueue q(1000, std::chrono::seconds(10));
  q.PushData(1, "a1");
  q.PushControl("{c}");
  q.Finish();
  EXPECT_FALSE(q.PushControl("{late}"));
  EXPECT_FALSE(q.PushData(1, "late"));
  q.PushLatest(2, "late");
  std::vector<Frame> batch;
  const auto start = Clock::now();
  ASSERT_TRUE(q.PopAll(&batch));
  EXPECT_EQ(Texts(batch), (std::vector<std::string>{"{c}", "a1"}));
  EXPECT_FALSE(q.PopAll(&batch));
  EXPECT_LT(Clock::now() - start, std::chrono::seconds(5)) << "the flush interval was waited for";
  EXPECT_FALSE(q.overflowed());
}

TEST(SendQueue, DropsTheBusiestChannelsOldestFramesWhenFull) {
  SendQueue q(100);
  const std::string big(30, 'x'), small(5, 's');
  q.PushData(1, small);  // channel 1: 5 bytes
  for (int i = 0; i < 3; ++i) q.PushData(2, big + std::to_string(i));  // channel 2: 93 bytes
  EXPECT_TRUE(q.PushData(1, small));  // 103 > 100: channel 2 (busiest) loses its oldest
  auto drops = q.TakeDrops();
  EXPECT_EQ(drops, (std::map<uint32_t, uint64_t>{{2, 1}}));
  EXPECT_TRUE(q.TakeDrops().empty());
  std::vector<Frame> batch;
  ASSERT_TRUE(q.PopAll(&batch));
  EXPECT_EQ(Texts(batch), (std::vector<std::string>{small, big + "1", big + "2", small}));
}

TEST(SendQueue, NeverExceedsTheLimitAndNeverBlocksAProducer) {
  SendQueue q(4096);
  for (int i = 0; i < 100000; ++i) q.PushData(static_cast<uint32_t>(i % 3), std::string(100, 'y'));
  EXPECT_LE(q.queued_bytes(), 4096u);
  uint64_t dropped = 0;
  for (const auto& [c, n] : q.TakeDrops()) dropped += n;
  EXPECT_EQ(dropped, 100000u - 40u);
}

TEST(SendQueue, AFrameLargerThanTheLimitIsDroppedItself) {
  SendQueue q(10);
  EXPECT_FALSE(q.PushData(1, std::string(11, 'z')));
  EXPECT_EQ(q.TakeDrops()[1], 1u);
}

TEST(SendQueue, CloseWakesTheConsumer) {
  SendQueue q(10);
  std::thread t([&] {
    std::vector<Frame> batch;
    EXPECT_FALSE(q.PopAll(&batch));
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  q.Close();
  t.join();
}

TEST(SendQueue, ASharedTailCountsAndIsSentAfterItsHead) {
  SendQueue q(30);
  auto sample = std::make_shared<const std::string>("0123456789");
  EXPECT_TRUE(q.PushData(1, "h1", true, sample));  // 2 + 10 bytes
  EXPECT_TRUE(q.PushData(2, "h2", true, sample));
  EXPECT_EQ(q.queued_bytes(), 24u);
  EXPECT_TRUE(q.PushData(3, "h3", true, sample));  // 36 > 30: channel 1 (tied busiest, first) loses its frame
  EXPECT_EQ(q.queued_bytes(), 24u);
  EXPECT_EQ(q.TakeDrops(), (std::map<uint32_t, uint64_t>{{1, 1}}));
  std::vector<Frame> batch;
  ASSERT_TRUE(q.PopAll(&batch));
  EXPECT_EQ(Texts(batch), (std::vector<std::string>{"h20123456789", "h30123456789"}));
}

// Waits (up to 10 s) until `done` holds; false if it never did.
template <typename F>
bool Eventually(F done) {
  for (int i = 0; i < 10000 && !done(); ++i) std::this_thread::sleep_for(milliseconds(1));
  return done();
}

// The first sample after a quiet spell wakes the idle consumer at once, even with a long interval.
TEST(SendQueue, AnIdleConsumerIsWokenByTheFirstSample) {
  SendQueue q(1000, std::chrono::hours(1));
  std::atomic<int> batches{0};
  std::thread consumer([&] {
    std::vector<Frame> batch;
    while (q.PopAll(&batch)) ++batches;
  });
  ASSERT_TRUE(Eventually([&] { return q.idle_waits() == 1; }));  // waiting for data, not on a timer
  q.PushData(1, "first");
  const bool woken = Eventually([&] { return batches.load() == 1; });
  q.Close();
  consumer.join();
  EXPECT_TRUE(woken) << "the first sample did not wake the idle consumer";
  EXPECT_EQ(q.wakeups_by_producers(), 1u);
}

// After a batch, data waits for the interval (no wake-up per sample); a control frame does not.
TEST(SendQueue, DataRightAfterABatchWaitsForTheIntervalButControlDoesNot) {
  SendQueue q(1000, std::chrono::hours(1));
  std::vector<Frame> batch;
  q.PushData(1, "a");
  ASSERT_TRUE(q.PopAll(&batch));  // the first batch: at once
  q.PushData(1, "b");
  std::atomic<bool> returned{false};
  std::thread consumer([&] {
    std::vector<Frame> second;
    EXPECT_TRUE(q.PopAll(&second));
    EXPECT_EQ(Texts(second), (std::vector<std::string>{"{c}", "b"}));
    returned = true;
  });
  std::this_thread::sleep_for(milliseconds(200));
  EXPECT_FALSE(returned.load()) << "data woke the consumer inside the interval";
  q.PushControl("{c}");
  consumer.join();
  EXPECT_TRUE(returned.load());
  EXPECT_EQ(q.wakeups_by_producers(), 0u);
}

// A fast stream is collected in batches, at most one per interval, on the consumer's timer: the
// producer wakes nobody (at most the very first sample, if the consumer was idle then).
TEST(SendQueue, AFastStreamIsHandedOutAtMostOncePerIntervalAndItsProducerWakesNobody) {
  const auto interval = milliseconds(20);
  SendQueue q(1 << 20, interval);
  std::atomic<int> batches{0}, frames{0};
  std::thread consumer([&] {
    std::vector<Frame> batch;
    while (q.PopAll(&batch)) {
      ++batches;
      frames += static_cast<int>(batch.size());
    }
  });
  const auto start = Clock::now();
  for (int i = 0; i < 2000; ++i) {  // about 5 kHz for about 0.4 s
    q.PushData(1, std::string(100, 'x'));
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  ASSERT_TRUE(Eventually([&] { return frames.load() == 2000; }));
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  q.Close();
  consumer.join();
  EXPECT_LE(batches.load(), elapsed / 0.020 + 2) << "over " << elapsed << " s";
  EXPECT_GE(batches.load(), 2);
  // A loaded machine may stall the producer past an interval now and then: the consumer then
  // goes idle and the next sample wakes it. Far from one per sample either way.
  EXPECT_LE(q.wakeups_by_producers(), 1u + q.idle_waits()) << "per-sample wake-ups";
  EXPECT_LT(q.wakeups_by_producers(), 100u);
}

// With a zero interval every sample that finds the consumer idle wakes it (the subject's page).
TEST(SendQueue, AZeroIntervalSendsEachSampleAtOnce) {
  SendQueue q(1000, milliseconds(0));
  std::atomic<int> batches{0};
  std::thread consumer([&] {
    std::vector<Frame> batch;
    while (q.PopAll(&batch)) ++batches;
  });
  for (int i = 1; i <= 3; ++i) {
    ASSERT_TRUE(Eventually([&] { return q.idle_waits() == static_cast<uint64_t>(i); }));
    q.PushData(1, "s");
    ASSERT_TRUE(Eventually([&] { return batches.load() == i; }));
  }
  q.Close();
  consumer.join();
  EXPECT_EQ(q.wakeups_by_producers(), 3u);
}

TEST(SendQueue, PushLatestKeepsOnlyTheNewestFrameOfItsChannel) {
  SendQueue q(1000);
  q.PushData(2, "other");
  q.PushLatest(1, "old");
  q.PushLatest(1, "new");
  EXPECT_EQ(q.queued_bytes(), 8u);
  EXPECT_TRUE(q.TakeDrops().empty());  // replaced, not dropped
  std::vector<Frame> batch;
  ASSERT_TRUE(q.PopAll(&batch));
  EXPECT_EQ(Texts(batch), (std::vector<std::string>{"other", "new"}));
}

TEST(SendQueue, PushLatestFromTwoProducersAtOnceNeverQueuesTwoFrames) {
  // Clearing the channel and queueing the new frame in separate lock holds let two producers
  // both clear, then both queue: two frames where "newest only" promises one. Each producer
  // looks right after its own push, when the other's frame would still be there.
  SendQueue q(1 << 20);
  constexpr int kEach = 200000;
  std::atomic<size_t> most{0};
  auto produce = [&](char who) {
    size_t seen = 0;
    for (int i = 0; i < kEach; ++i) {
      q.PushLatest(1, std::string(1, who));
      seen = std::max(seen, q.queued_bytes());
    }
    size_t m = most.load();
    while (seen > m && !most.compare_exchange_weak(m, seen)) {
    }
  };
  std::thread a(produce, 'a'), b(produce, 'b');
  a.join();
  b.join();
  EXPECT_EQ(most.load(), 1u);
  EXPECT_EQ(q.queued_bytes(), 1u);
}

}  // namespace
}  // namespace dyad::web
