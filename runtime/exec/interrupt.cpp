#include "dyad/interrupt.hpp"

#include <poll.h>
#include <sys/eventfd.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>

namespace dyad {

InterruptWatcher::InterruptWatcher(std::function<void(int)> on_signal) : on_signal_(std::move(on_signal)) {
  sigemptyset(&set_);
  sigaddset(&set_, SIGINT);
  sigaddset(&set_, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &set_, &old_);
  signal_fd_ = signalfd(-1, &set_, SFD_CLOEXEC);
  wake_fd_ = eventfd(0, EFD_CLOEXEC);
  thread_ = std::thread([this] { Watch(); });
}

InterruptWatcher::~InterruptWatcher() {
  done_.store(true, std::memory_order_release);
  if (wake_fd_ >= 0) {
    const uint64_t one = 1;
    [[maybe_unused]] const ssize_t n = write(wake_fd_, &one, sizeof one);
  }
  thread_.join();
  if (signal_fd_ >= 0) close(signal_fd_);
  if (wake_fd_ >= 0) close(wake_fd_);
  pthread_sigmask(SIG_SETMASK, &old_, nullptr);
}

int InterruptWatcher::NextSignal() {
  if (looking_ || signal_fd_ < 0 || wake_fd_ < 0) {
    // No descriptor to spare (EMFILE), or they failed: look every 50 ms instead of sleeping until woken.
    timespec ts{0, 50'000'000};
    return sigtimedwait(&set_, nullptr, &ts);
  }
  pollfd fds[2] = {{signal_fd_, POLLIN, 0}, {wake_fd_, POLLIN, 0}};
  const int ready = poll(fds, 2, -1);
  if (ready < 0) return errno == EINTR ? 0 : LookFromNowOn("poll", errno);
  if (fds[1].revents & POLLIN) return 0;  // woken to end
  // A descriptor closed under it (POLLNVAL) or in error: polling again would return at once.
  const int events = fds[0].revents | fds[1].revents;
  if ((events & (POLLERR | POLLNVAL)) || !(fds[0].revents & POLLIN))
    return LookFromNowOn("poll", (events & POLLNVAL) ? EBADF : EIO);
  signalfd_siginfo info{};
  const ssize_t n = read(signal_fd_, &info, sizeof info);
  if (n == static_cast<ssize_t>(sizeof info)) return static_cast<int>(info.ssi_signo);
  if (n < 0 && errno == EINTR) return 0;
  return LookFromNowOn("read", n < 0 ? errno : EIO);
}

// The signal stays pending when poll or read fails (blocked in every thread, not taken):
// sigtimedwait takes it.
int InterruptWatcher::LookFromNowOn(const char* call, int err) {
  const char* name = strerrorname_np(err);
  std::fprintf(stderr,
               "dyad: interrupt watcher: %s on its signalfd failed (%s: %s); looking for signals every 50 ms from now on\n", call,
               name != nullptr ? name : "errno", std::strerror(err));
  looking_ = true;
  return 0;
}

// Sleeps until a signal or the destructor: no periodic wake-up (a dyad process is often idle, and
// a study server runs dozens of them).
void InterruptWatcher::Watch() {
  while (!done_.load(std::memory_order_acquire)) {
    const int sig = NextSignal();
    if (sig <= 0 || done_.load(std::memory_order_acquire)) continue;
    int expected = 0;
    if (!signal_.compare_exchange_strong(expected, sig)) {
      std::fprintf(stderr, "dyad: second signal (%s), exiting now\n", SignalName(sig));
      _exit(ExitCodeForSignal(sig));
    }
    if (on_signal_) on_signal_(sig);
  }
}

const char* SignalName(int signal) {
  switch (signal) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGKILL: return "SIGKILL";
    case SIGSEGV: return "SIGSEGV";
    case SIGABRT: return "SIGABRT";
    case SIGBUS: return "SIGBUS";
    case SIGFPE: return "SIGFPE";
    case SIGILL: return "SIGILL";
    case SIGHUP: return "SIGHUP";
    case SIGPIPE: return "SIGPIPE";
    case SIGQUIT: return "SIGQUIT";
    default: return "signal";
  }
}

}  // namespace dyad
