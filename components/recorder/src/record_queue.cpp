#include "record_queue.hpp"

#include <algorithm>
#include <chrono>

namespace dyad::recorder {

RecordQueue::RecordQueue(size_t capacity_bytes)
    : arena_bytes_(std::max<size_t>(capacity_bytes / 2, 1024)), wake_bytes_(std::min<size_t>(arena_bytes_ / 4, 256 * 1024)) {
  filling_.bytes_.reserve(arena_bytes_);
}

bool RecordQueue::Push(const RecordEntry& entry, std::span<const uint8_t> payload) {
  const size_t need = sizeof(RecordEntry) + payload.size();
  std::unique_lock<std::mutex> lock(mutex_);
  if (!closed_ && !filling_.bytes_.empty() && filling_.bytes_.size() + need > arena_bytes_) {
    ++producer_waits_;
    consumer_waiting_ = false;
    not_empty_.notify_one();
    not_full_.wait(lock, [&] { return closed_ || filling_.bytes_.empty() || filling_.bytes_.size() + need <= arena_bytes_; });
  }
  if (closed_) return false;
  auto& b = filling_.bytes_;
  const size_t at = b.size();
  b.resize(at + need);  // within capacity except for an oversized first record
  RecordEntry e = entry;
  e.size = static_cast<uint32_t>(payload.size());
  std::memcpy(b.data() + at, &e, sizeof e);
  if (!payload.empty()) std::memcpy(b.data() + at + sizeof e, payload.data(), payload.size());
  ++filling_.count_;
  high_water_ = std::max(high_water_, b.size());
  // Wake an idle consumer only once there is a worthwhile batch: a wake-up per sample would cost
  // the publisher a futex call each time. Below the threshold the consumer's timeout collects it.
  if (consumer_waiting_ && b.size() >= wake_bytes_) {
    consumer_waiting_ = false;
    not_empty_.notify_one();
  }
  return true;
}

bool RecordQueue::TakeBatch(RecordBatch* batch, int timeout_ms) {
  batch->bytes_.clear();
  batch->count_ = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  if (filling_.bytes_.size() < wake_bytes_ && !closed_) {
    consumer_waiting_ = true;
    not_empty_.wait_for(lock, std::chrono::milliseconds(timeout_ms), [&] { return closed_ || filling_.bytes_.size() >= wake_bytes_; });
    consumer_waiting_ = false;
  }
  if (filling_.bytes_.empty()) return !closed_;
  std::swap(batch->bytes_, filling_.bytes_);
  std::swap(batch->count_, filling_.count_);
  if (filling_.bytes_.capacity() < arena_bytes_) filling_.bytes_.reserve(arena_bytes_);
  lock.unlock();
  not_full_.notify_all();
  return true;
}

void RecordQueue::Close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  not_empty_.notify_all();
  not_full_.notify_all();
}

size_t RecordQueue::high_water_bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return high_water_;
}

uint64_t RecordQueue::producer_waits() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return producer_waits_;
}

}  // namespace dyad::recorder
