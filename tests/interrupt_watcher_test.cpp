// InterruptWatcher: a process-directed SIGTERM reaches on_signal on the watcher's thread, and an
// idle watcher does not wake (it used to poll every 50 ms: 20 wake-ups a second in every dyad
// process, dozens of them on a study server).
#include "dyad/interrupt.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace dyad {
namespace {

long VoluntarySwitches() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_nvcsw;
}

TEST(InterruptWatcher, ASignalReachesTheCallbackOffTheSignalledThread) {
  std::mutex mutex;
  std::condition_variable heard;
  int got = 0;
  std::thread::id on;
  {
    InterruptWatcher watcher([&](int sig) {
      std::lock_guard<std::mutex> lock(mutex);
      got = sig;
      on = std::this_thread::get_id();
      heard.notify_all();
    });
    ASSERT_EQ(kill(getpid(), SIGTERM), 0);
    std::unique_lock<std::mutex> lock(mutex);
    ASSERT_TRUE(heard.wait_for(lock, std::chrono::seconds(5), [&] { return got != 0; }));
    EXPECT_EQ(got, SIGTERM);
    EXPECT_NE(on, std::this_thread::get_id());
    EXPECT_EQ(watcher.signal(), SIGTERM);
    EXPECT_TRUE(watcher.interrupted());
  }
  // The mask is restored: SIGTERM is no longer blocked here.
  sigset_t now;
  pthread_sigmask(SIG_SETMASK, nullptr, &now);
  EXPECT_FALSE(sigismember(&now, SIGTERM));
}

TEST(InterruptWatcher, AnIdleWatcherSleeps) {
  long woke = 0;
  {
    InterruptWatcher watcher;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the thread started and asleep
    const long before = VoluntarySwitches();
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));
    woke = VoluntarySwitches() - before;  // this thread's sleep is one; 50 ms polling made 20 more
  }
  EXPECT_LE(woke, 4);
  EXPECT_EQ(InterruptWatcher().signal(), 0);  // made and ended at once, woken by its destructor
}

}  // namespace
}  // namespace dyad
