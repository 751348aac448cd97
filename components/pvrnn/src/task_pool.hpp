// Internal: a fixed set of persistent threads that run the tasks 0..n-1 of one call together
// (the caller's thread works too). Which thread runs a task varies; callers keep results per
// task and combine them in task order, so results never depend on the thread count.
//
// Contract
// - `TaskPool(threads)`: threads - 1 workers are started here and joined by the destructor.
// - `Run(n, f)` calls f(i) once for every i in 0..n-1 and returns when all have returned.
//   No allocation. Not reentrant: one Run at a time, from one thread.
// - Idle workers poll ~400 us (an epoch follows the last within tens of microseconds), then
//   sleep on a futex; the caller waits for the last task with WaitUntil.
#pragma once

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

namespace dyad::pvrnn::internal {

inline void CpuRelax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

// Returns once `done()` is true, for waits inside one call of Run (the awaited task is running
// on another thread): polls ~50 us (a pause is ~20 ns here), then yields the core between polls
// so that, when other processes keep the cores busy, the awaited thread gets to run.
template <typename Done>
void WaitUntil(Done done) {
  for (int spin = 0; !done(); ++spin) {
    if (spin < 2500)
      CpuRelax();
    else
      std::this_thread::yield();
  }
}

class TaskPool {
 public:
  explicit TaskPool(int threads);
  ~TaskPool();
  TaskPool(const TaskPool&) = delete;
  TaskPool& operator=(const TaskPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  template <typename F>
  void Run(int tasks, F& f) {
    RunRaw(tasks, [](void* ctx, int i) { (*static_cast<F*>(ctx))(i); }, &f);
  }

 private:
  using Fn = void (*)(void*, int);
  void RunRaw(int tasks, Fn fn, void* ctx);
  void WorkerLoop();
  void Drain(uint32_t generation);

  std::vector<std::thread> workers_;
  // Claim word: generation in the high 32 bits, next task index in the low 32; a worker that
  // wakes late cannot claim a task of a later call.
  std::atomic<uint64_t> next_{0};
  std::atomic<uint32_t> generation_{0};
  std::atomic<int> tasks_{0}, done_{0};
  std::atomic<Fn> fn_{nullptr};
  std::atomic<void*> ctx_{nullptr};
  std::atomic<bool> stop_{false};
};

}  // namespace dyad::pvrnn::internal
