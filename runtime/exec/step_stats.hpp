// StepStats — timing of one component's steps: count, duration (mean, p99, max), start jitter,
// deadline misses; and of its serialized-subscription callbacks (count, mean, max), which run
// outside its steps, on the delivering thread. O(1) per step, no allocation: durations go into a log-linear histogram
// (16 sub-buckets per power of two, so a percentile is within ~6% of the true value).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>

namespace dyad {

class StepStats {
 public:
  struct Snapshot {
    uint64_t steps = 0;
    double mean_s = 0, p99_s = 0, max_s = 0;
    double jitter_mean_s = 0, jitter_max_s = 0;
    uint64_t deadline_misses = 0;
    uint64_t deliveries = 0;  // serialized-subscription callbacks
    double delivery_mean_s = 0, delivery_max_s = 0;
  };

  // duration: step wall time; jitter: |actual start - scheduled start| (0 for triggered steps).
  // One caller at a time (a component's steps never overlap): no lock, see seq_.
  void Record(int64_t duration_ns, int64_t jitter_ns, bool missed_deadline);
  // duration of one serialized-subscription callback of this component.
  void RecordDelivery(int64_t duration_ns);
  Snapshot Get() const;  // thread-safe against Record

  // Histogram bucket of a duration, and the bucket's upper bound (exposed for tests).
  static int Bucket(int64_t ns);
  static int64_t BucketUpper(int bucket);

 private:
  static constexpr int kSub = 16;
  static constexpr int kBuckets = 64 * kSub;
  // The steps' figures have one writer and are read by Get() as a sequence lock: seq_ is odd
  // while Record writes, and Get() retries a read that a Record overlapped (no lock on the step
  // path; every field atomic, relaxed, so the race is defined). Deliveries come from several
  // threads and keep the mutex.
  std::atomic<uint64_t> seq_{0};
  std::array<std::atomic<uint64_t>, kBuckets> histogram_{};
  std::atomic<uint64_t> steps_{0}, misses_{0};
  std::atomic<double> sum_ns_{0}, jitter_sum_ns_{0};
  std::atomic<int64_t> max_ns_{0}, jitter_max_ns_{0};
  mutable std::mutex mutex_;  // the deliveries' figures
  uint64_t deliveries_ = 0;
  double delivery_sum_ns_ = 0;
  int64_t delivery_max_ns_ = 0;
};

}  // namespace dyad
