// SendQueue: bounded, never blocks producers, drops the busiest channel's oldest frames first,
// never drops control frames, keeps data in push order.
#include "send_queue.hpp"

#include <gtest/gtest.h>

#include <thread>

namespace dyad::web {
namespace {

TEST(SendQueue, KeepsPushOrderAcrossChannelsAndControlFirst) {
  SendQueue q(1000);
  q.PushData(1, "a1");
  q.PushData(2, "b1");
  q.PushData(1, "a2");
  q.PushControl("{c}");
  Frame f;
  std::vector<std::string> out;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(q.Pop(&f));
    out.push_back(f.bytes);
  }
  EXPECT_EQ(out, (std::vector<std::string>{"{c}", "a1", "b1", "a2"}));
  EXPECT_EQ(q.queued_bytes(), 0u);
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
  Frame f;
  std::vector<std::string> out;
  while (q.queued_bytes() > 0 && q.Pop(&f)) out.push_back(f.bytes);
  EXPECT_EQ(out, (std::vector<std::string>{small, big + "1", big + "2", small}));
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
    Frame f;
    EXPECT_FALSE(q.Pop(&f));
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  q.Close();
  t.join();
}

}  // namespace
}  // namespace dyad::web
