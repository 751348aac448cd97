// dyad/interrupt.hpp — Ctrl-C (SIGINT) and SIGTERM for every dyad command, one mechanism.
//
// An InterruptWatcher blocks SIGINT and SIGTERM in the thread that creates it, so every thread
// started afterwards (Fast DDS's, components', trainers') inherits the block, and takes them on
// a thread of its own, asleep on a signalfd until one comes (no periodic wake-up: a study server
// runs dozens of dyad processes). Should poll or read on the signalfd fail (a descriptor closed
// under it, say), it says so once on stderr, naming the errno, and looks every 50 ms from then on
// (sigtimedwait, as without descriptors to spare): never a busy loop, and no signal lost (it
// stays pending until taken). So a signal never interrupts a system call of a Fast DDS
// thread, never runs code in a signal handler, and `on_signal` runs on an ordinary thread
// (it may lock, log, call Executor::RequestStop). A second signal while the first is being
// handled ends the process at once (exit 128 + signal): Ctrl-C twice always works.
//
// Create it first, before any participant or worker thread; destroy it last. One at a time per
// process (the block is process-wide in effect). The destructor restores the previous mask.
//
//   dyad::InterruptWatcher interrupt([&](int sig) { executor.RequestStop(SignalName(sig)); });
//   ... run ...
//   if (interrupt.signal() != 0) return ExitCodeForSignal(interrupt.signal());
//
// Exit codes: a command ended by a signal exits 128 + signal (130 for Ctrl-C), the shell's
// convention, after saying "interrupted (SIGINT)" and finishing cleanly (recordings closed,
// checkpoints written): scripts can tell "stopped by a person" from success (0) and failure.
#pragma once

#include <signal.h>

#include <atomic>
#include <functional>
#include <thread>

namespace dyad {

class InterruptWatcher {
 public:
  explicit InterruptWatcher(std::function<void(int signal)> on_signal = nullptr);
  ~InterruptWatcher();
  InterruptWatcher(const InterruptWatcher&) = delete;
  InterruptWatcher& operator=(const InterruptWatcher&) = delete;

  // The first signal taken (SIGINT or SIGTERM), 0 if none. Thread-safe.
  int signal() const { return signal_.load(std::memory_order_acquire); }
  bool interrupted() const { return signal() != 0; }

 private:
  int NextSignal();  // the next SIGINT/SIGTERM, or 0 (woken to end, or nothing)
  int LookFromNowOn(const char* call, int err);  // says why once, sets looking_; returns 0
  void Watch();

  sigset_t set_, old_;
  int signal_fd_ = -1, wake_fd_ = -1;  // -1: polling every 50 ms instead
  bool looking_ = false;               // they failed: polling every 50 ms (the watcher's thread only)
  std::function<void(int)> on_signal_;
  std::atomic<int> signal_{0};
  std::atomic<bool> done_{false};
  std::thread thread_;
};

// "SIGINT", "SIGTERM", "SIGKILL" and the other signals that end a process, or "signal".
const char* SignalName(int signal);
// 128 + signal.
inline int ExitCodeForSignal(int signal) { return 128 + signal; }

}  // namespace dyad
