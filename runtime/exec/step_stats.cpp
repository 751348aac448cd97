#include "exec/step_stats.hpp"

#include <algorithm>
#include <bit>

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

void StepStats::Record(int64_t duration_ns, int64_t jitter_ns, bool missed_deadline) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++histogram_[Bucket(duration_ns)];
  ++steps_;
  sum_ns_ += static_cast<double>(duration_ns);
  max_ns_ = std::max(max_ns_, duration_ns);
  jitter_sum_ns_ += static_cast<double>(jitter_ns);
  jitter_max_ns_ = std::max(jitter_max_ns_, jitter_ns);
  if (missed_deadline) ++misses_;
}

void StepStats::RecordDelivery(int64_t duration_ns) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++deliveries_;
  delivery_sum_ns_ += static_cast<double>(duration_ns);
  delivery_max_ns_ = std::max(delivery_max_ns_, duration_ns);
}

StepStats::Snapshot StepStats::Get() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Snapshot s;
  s.deliveries = deliveries_;
  if (deliveries_ > 0) {
    s.delivery_mean_s = delivery_sum_ns_ / static_cast<double>(deliveries_) * 1e-9;
    s.delivery_max_s = static_cast<double>(delivery_max_ns_) * 1e-9;
  }
  s.steps = steps_;
  s.deadline_misses = misses_;
  if (steps_ == 0) return s;
  s.mean_s = sum_ns_ / static_cast<double>(steps_) * 1e-9;
  s.max_s = static_cast<double>(max_ns_) * 1e-9;
  s.jitter_mean_s = jitter_sum_ns_ / static_cast<double>(steps_) * 1e-9;
  s.jitter_max_s = static_cast<double>(jitter_max_ns_) * 1e-9;
  const uint64_t target = (steps_ * 99 + 99) / 100;  // ceil(0.99 n)
  uint64_t seen = 0;
  for (int b = 0; b < kBuckets; ++b) {
    seen += histogram_[b];
    if (seen >= target) {
      s.p99_s = static_cast<double>(std::min(BucketUpper(b), max_ns_)) * 1e-9;
      break;
    }
  }
  return s;
}

}  // namespace dyad
