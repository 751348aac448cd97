/// RecordQueue: hands samples from DDS delivery threads to the recorder's writer thread.
///
/// Two byte arenas of `capacity_bytes / 2` each: producers append records (a fixed-size entry
/// plus the payload bytes) to the filling arena under a mutex; the consumer swaps the arenas and
/// writes the full one without holding the lock. Nothing is ever dropped: a producer that finds
/// the filling arena full waits until the consumer swaps (back-pressure on the publisher rather
/// than loss). A single record larger than an arena is accepted into an empty arena, which grows.
///
/// Steady state does not allocate (the arenas keep their capacity). An idle consumer is woken
/// only once a quarter of an arena (at most 256 KiB) has filled, or by its own timeout, never per
/// push: a push costs a lock, a memcpy and an unlock.
///
/// Thread-safety: Push() from any number of threads; TakeBatch() from one consumer thread.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <span>
#include <vector>

namespace dyad::recorder {

struct RecordEntry {
  uint16_t channel = 0;
  uint32_t sequence = 0;
  uint64_t log_time = 0;
  uint64_t publish_time = 0;
  uint32_t size = 0;  // payload bytes following the entry in the arena
};

// A batch the consumer owns until its next TakeBatch(): entries with their payload bytes.
class RecordBatch {
 public:
  template <class F>  // F(const RecordEntry&, std::span<const uint8_t>)
  void ForEach(F&& f) const {
    size_t off = 0;
    while (off < bytes_.size()) {
      RecordEntry e;
      std::memcpy(&e, bytes_.data() + off, sizeof e);
      off += sizeof e;
      f(e, std::span<const uint8_t>(bytes_.data() + off, e.size));
      off += e.size;
    }
  }
  size_t size_bytes() const { return bytes_.size(); }
  bool empty() const { return bytes_.empty(); }
  uint64_t count() const { return count_; }

 private:
  friend class RecordQueue;
  std::vector<uint8_t> bytes_;
  uint64_t count_ = 0;
};

class RecordQueue {
 public:
  // REQUIRES: capacity_bytes >= 2 KiB.
  explicit RecordQueue(size_t capacity_bytes);

  // Appends one record; blocks while the filling arena is full. Returns false (dropping nothing
  // the caller must care about) only after Close().
  bool Push(const RecordEntry& entry, std::span<const uint8_t> payload);

  // Waits up to `timeout_ms` for a worthwhile batch (or Close()), then swaps what there is into
  // *batch (whose previous contents are discarded); the timeout bounds the hand-over latency. Returns false when the queue is closed and empty: the consumer is done.
  bool TakeBatch(RecordBatch* batch, int timeout_ms);

  // After Close(), Push() refuses and TakeBatch() returns what is left, then false.
  void Close();

  // Largest fill of an arena seen, in bytes; and how often a producer had to wait.
  size_t high_water_bytes() const;
  uint64_t producer_waits() const;

 private:
  const size_t arena_bytes_;
  const size_t wake_bytes_;
  mutable std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  RecordBatch filling_;
  bool closed_ = false;
  bool consumer_waiting_ = false;
  size_t high_water_ = 0;
  uint64_t producer_waits_ = 0;
};

}  // namespace dyad::recorder
