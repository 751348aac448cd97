#include "exec/step_stats.hpp"

#include <algorithm>
#include <bit>
#include <thread>

namespace dyad {

int StepStats::Bucket(int64_t ns) {
  if (ns < kSub) return static_cast<int>(std::max<int64_t>(ns, 0));
  const uint64_t v = static_cast<uint64_t>(ns);
  const int exp = 63 - std::countl_zero(v);           // v in [2^exp, 2^(exp+1))
  const int sub = static_cast<int>((v >> (exp - 4)) & (kSub - 1));  // next 4 bits
  return std::min((exp - 3) * kSub + sub, kBuckets - 1);
}

int64_t StepStats::BucketUpper(int bucket) {
  if (bucket < kSub) return bucket;
  const int exp = bucket / kSub + 3;
  const int sub = bucket % kSub;
  return static_cast<int64_t>(((uint64_t{kSub} + sub + 1) << (exp - 4)) - 1);
}

namespace {
// The single writer's increment and maximum (no read-modify-write instruction needed).
template <class T>
void Add(std::atomic<T>& a, T v) {
  a.store(a.load(std::memory_order_relaxed) + v, std::memory_order_relaxed);
}
void Max(std::atomic<int64_t>& a, int64_t v) {
  if (v > a.load(std::memory_order_relaxed)) a.store(v, std::memory_order_relaxed);
}
}  // namespace

void StepStats::Record(int64_t duration_ns, int64_t jitter_ns, bool missed_deadline) {
  const uint64_t seq = seq_.load(std::memory_order_relaxed);
  seq_.store(seq + 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);  // odd before any field changes
  Add<uint64_t>(histogram_[Bucket(duration_ns)], 1);
  Add<uint64_t>(steps_, 1);
  Add(sum_ns_, static_cast<double>(duration_ns));
  Max(max_ns_, duration_ns);
  Add(jitter_sum_ns_, static_cast<double>(jitter_ns));
  Max(jitter_max_ns_, jitter_ns);
  if (missed_deadline) Add<uint64_t>(misses_, 1);
  seq_.store(seq + 2, std::memory_order_release);
}

void StepStats::RecordDelivery(int64_t duration_ns) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++deliveries_;
  delivery_sum_ns_ += static_cast<double>(duration_ns);
  delivery_max_ns_ = std::max(delivery_max_ns_, duration_ns);
}

StepStats::Snapshot StepStats::Get() const {
  Snapshot s;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    s.deliveries = deliveries_;
    if (deliveries_ > 0) {
      s.delivery_mean_s = delivery_sum_ns_ / static_cast<double>(deliveries_) * 1e-9;
      s.delivery_max_s = static_cast<double>(delivery_max_ns_) * 1e-9;
    }
  }
  std::array<uint64_t, kBuckets> histogram;
  double sum_ns = 0, jitter_sum_ns = 0;
  int64_t max_ns = 0, jitter_max_ns = 0;
  for (;;) {  // a consistent copy: no Record began or ended meanwhile
    const uint64_t seq = seq_.load(std::memory_order_acquire);
    if (seq % 2 == 0) {
      for (int b = 0; b < kBuckets; ++b) histogram[b] = histogram_[b].load(std::memory_order_relaxed);
      s.steps = steps_.load(std::memory_order_relaxed);
      s.deadline_misses = misses_.load(std::memory_order_relaxed);
      sum_ns = sum_ns_.load(std::memory_order_relaxed);
      jitter_sum_ns = jitter_sum_ns_.load(std::memory_order_relaxed);
      max_ns = max_ns_.load(std::memory_order_relaxed);
      jitter_max_ns = jitter_max_ns_.load(std::memory_order_relaxed);
      std::atomic_thread_fence(std::memory_order_acquire);
      if (seq_.load(std::memory_order_relaxed) == seq) break;
    }
    std::this_thread::yield();
  }
  if (s.steps == 0) return s;
  const double steps = static_cast<double>(s.steps);
  s.mean_s = sum_ns / steps * 1e-9;
  s.max_s = static_cast<double>(max_ns) * 1e-9;
  s.jitter_mean_s = jitter_sum_ns / steps * 1e-9;
  s.jitter_max_s = static_cast<double>(jitter_max_ns) * 1e-9;
  const uint64_t target = (s.steps * 99 + 99) / 100;  // ceil(0.99 n)
  uint64_t seen = 0;
  for (int b = 0; b < kBuckets; ++b) {
    seen += histogram[b];
    if (seen >= target) {
      s.p99_s = static_cast<double>(std::min(BucketUpper(b), max_ns)) * 1e-9;
      break;
    }
  }
  return s;
}

}  // namespace dyad
