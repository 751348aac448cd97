// InterruptWatcher: a process-directed SIGTERM reaches on_signal on the watcher's thread, an
// idle watcher does not wake (it used to poll every 50 ms: 20 wake-ups a second in every dyad
// process, dozens of them on a study server), and a watcher whose signalfd fails (closed under
// it) still takes the signal, without spinning. Each case runs in a forked child: a signal sent to
// a process whose other threads (earlier tests' Fast DDS threads) do not block it would end it,
// and the wake-ups counted are the whole process's.
#include "dyad/interrupt.hpp"

#include <dirent.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <functional>
#include <set>
#include <string>
#include <string_view>
#include <thread>

namespace dyad {
namespace {

// fn's result as the exit code of a child that runs only it (-1: it did not exit normally).
int InChild(const std::function<int()>& fn) {
  const pid_t pid = fork();
  if (pid == 0) _exit(fn());
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, 0) != pid || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

TEST(InterruptWatcher, ASignalReachesTheCallbackOffTheSignalledThread) {
  const int code = InChild([] {
    std::atomic<int> got{0};
    std::atomic<bool> other_thread{false};
    const std::thread::id main = std::this_thread::get_id();
    {
      InterruptWatcher watcher([&](int sig) {
        other_thread = std::this_thread::get_id() != main;
        got = sig;
      });
      if (kill(getpid(), SIGTERM) != 0) return 10;
      for (int i = 0; i < 500 && got == 0; i++) std::this_thread::sleep_for(std::chrono::milliseconds(10));
      if (got != SIGTERM) return 11;  // not heard within 5 s
      if (!other_thread) return 12;
      if (watcher.signal() != SIGTERM || !watcher.interrupted()) return 13;
    }
    sigset_t now;
    pthread_sigmask(SIG_SETMASK, nullptr, &now);
    return sigismember(&now, SIGTERM) ? 14 : 0;  // the mask restored
  });
  EXPECT_EQ(code, 0) << "10: kill failed, 11: no callback in 5 s, 12: called on the signalled thread, "
                        "13: signal() wrong, 14: mask not restored, -1: the child died";
}

TEST(InterruptWatcher, AnIdleWatcherSleeps) {
  const int woke = InChild([] {
    long woke = 0;
    {
      InterruptWatcher watcher;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));  // the thread started and asleep
      rusage before{}, after{};
      getrusage(RUSAGE_SELF, &before);
      std::this_thread::sleep_for(std::chrono::milliseconds(1000));
      getrusage(RUSAGE_SELF, &after);
      woke = after.ru_nvcsw - before.ru_nvcsw;  // this thread's sleep is one; 50 ms polling made 20 more
    }
    const int unsignalled = InterruptWatcher().signal();  // made and ended at once, woken by its destructor
    return unsignalled == 0 ? static_cast<int>(std::min(woke, 100L)) : 101;
  });
  EXPECT_GE(woke, 0) << "the child died";
  EXPECT_LE(woke, 4) << "voluntary context switches of an idle process in 1 s (101: a signal seen)";
}

// The process's open signalfds (/proc/self/fd's links to "anon_inode:[signalfd]").
std::set<int> SignalFds() {
  std::set<int> fds;
  DIR* dir = opendir("/proc/self/fd");
  if (dir == nullptr) return fds;
  while (const dirent* e = readdir(dir)) {
    char target[64] = {};
    const std::string link = std::string("/proc/self/fd/") + e->d_name;
    if (readlink(link.c_str(), target, sizeof target - 1) > 0 && std::string_view(target) == "anon_inode:[signalfd]")
      fds.insert(std::atoi(e->d_name));
  }
  closedir(dir);
  return fds;
}

double CpuMs() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) * 1e3 +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) / 1e3;
}

// Its signalfd closed under it: poll then reports POLLNVAL at once and read fails (EBADF). The
// watcher said nothing, polled again at once (100 % of a core) and never took the signal; now it
// says why once and looks every 50 ms, as without descriptors.
TEST(InterruptWatcher, ASignalfdClosedUnderItFallsBackToLookingEvery50Ms) {
  const int code = InChild([] {
    std::atomic<int> got{0};
    const std::set<int> before = SignalFds();
    InterruptWatcher watcher([&](int sig) { got = sig; });
    const int result = [&] {
      std::set<int> mine = SignalFds();
      for (int fd : before) mine.erase(fd);
      if (mine.size() != 1) return 20;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the watcher asleep in poll
      close(*mine.begin());
      if (kill(getpid(), SIGTERM) != 0) return 21;
      const double cpu = CpuMs();
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
      if (CpuMs() - cpu > 100) return 22;  // spinning: ~300 ms of CPU; looking every 50 ms: < 1 ms
      for (int i = 0; i < 200 && got == 0; i++) std::this_thread::sleep_for(std::chrono::milliseconds(10));
      return got == SIGTERM && watcher.signal() == SIGTERM ? 0 : 23;
    }();
    std::signal(SIGTERM, SIG_IGN);  // a SIGTERM left pending must not end the child when the mask is restored
    return result;
  });
  EXPECT_EQ(code, 0) << "20: not one new signalfd, 21: kill failed, 22: the watcher spun (over 100 ms of CPU in 300 ms), "
                        "23: the SIGTERM not taken within 2 s, -1: the child died";
}

}  // namespace
}  // namespace dyad
