#include "task_pool.hpp"

namespace dyad::pvrnn::internal {

namespace {
// An idle worker polls ~400 us before sleeping: waking it from the futex costs tens of
// microseconds in this VM, more than the serial part between two epochs.
constexpr int kIdleSpins = 20000;
}  // namespace

TaskPool::TaskPool(int threads) {
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { WorkerLoop(); });
}

TaskPool::~TaskPool() {
  stop_.store(true);
  generation_.fetch_add(1);
  generation_.notify_all();
  for (auto& t : workers_) t.join();
}

void TaskPool::RunRaw(int tasks, Fn fn, void* ctx) {
  if (workers_.empty()) {
    for (int i = 0; i < tasks; ++i) fn(ctx, i);
    return;
  }
  const uint32_t gen = generation_.load(std::memory_order_relaxed) + 1;
  fn_.store(fn, std::memory_order_relaxed);
  ctx_.store(ctx, std::memory_order_relaxed);
  tasks_.store(tasks, std::memory_order_relaxed);
  done_.store(0, std::memory_order_relaxed);
  next_.store(static_cast<uint64_t>(gen) << 32, std::memory_order_release);
  generation_.store(gen, std::memory_order_release);
  generation_.notify_all();
  Drain(gen);
  WaitUntil([this, tasks] { return done_.load(std::memory_order_acquire) == tasks; });
}

void TaskPool::Drain(uint32_t gen) {
  uint64_t v = next_.load(std::memory_order_acquire);
  while (static_cast<uint32_t>(v >> 32) == gen) {
    const int i = static_cast<int>(v & 0xffffffffu);
    if (i >= tasks_.load(std::memory_order_relaxed)) return;
    if (!next_.compare_exchange_weak(v, v + 1, std::memory_order_acq_rel)) continue;
    fn_.load(std::memory_order_relaxed)(ctx_.load(std::memory_order_relaxed), i);
    done_.fetch_add(1, std::memory_order_acq_rel);
    v = next_.load(std::memory_order_acquire);
  }
}

void TaskPool::WorkerLoop() {
  uint32_t seen = 0;
  while (true) {
    uint32_t gen = generation_.load(std::memory_order_acquire);
    for (int spin = 0; gen == seen && spin < kIdleSpins; ++spin) {
      CpuRelax();
      gen = generation_.load(std::memory_order_acquire);
    }
    if (gen == seen) {
      generation_.wait(seen, std::memory_order_acquire);
      continue;
    }
    seen = gen;
    if (stop_.load()) return;
    Drain(gen);
  }
}

}  // namespace dyad::pvrnn::internal
