#include "dyad/interrupt.hpp"

#include <unistd.h>

#include <cstdio>

namespace dyad {

InterruptWatcher::InterruptWatcher(std::function<void(int)> on_signal) : on_signal_(std::move(on_signal)) {
  sigemptyset(&set_);
  sigaddset(&set_, SIGINT);
  sigaddset(&set_, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &set_, &old_);
  thread_ = std::thread([this] {
    while (!done_.load(std::memory_order_acquire)) {
      timespec ts{0, 50'000'000};
      const int sig = sigtimedwait(&set_, nullptr, &ts);
      if (sig <= 0) continue;
      int expected = 0;
      if (!signal_.compare_exchange_strong(expected, sig)) {
        std::fprintf(stderr, "dyad: second signal (%s), exiting now\n", SignalName(sig));
        _exit(ExitCodeForSignal(sig));
      }
      if (on_signal_) on_signal_(sig);
    }
  });
}

InterruptWatcher::~InterruptWatcher() {
  done_.store(true, std::memory_order_release);
  thread_.join();
  pthread_sigmask(SIG_SETMASK, &old_, nullptr);
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
