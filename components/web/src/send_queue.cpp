#include "send_queue.hpp"

#include <algorithm>

namespace dyad::web {

bool SendQueue::PushControl(std::string json) {
  bool queued = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_ || finishing_) return false;
    if (control_bytes_ + json.size() > limit_) {
      closed_ = overflowed_ = true;
    } else {
      control_bytes_ += json.size();
      control_.push_back(std::move(json));
      queued = true;
    }
  }
  cv_.notify_all();
  return queued;
}

bool SendQueue::overflowed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return overflowed_;
}

bool SendQueue::PushData(uint32_t channel, std::string bytes, bool binary, std::shared_ptr<const std::string> tail) {
  bool queued = false, wake = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    queued = PushDataLocked(channel, Frame{binary, std::move(bytes), std::move(tail), channel, 0}, &wake);
  }
  if (wake) cv_.notify_one();
  return queued;
}

void SendQueue::PushLatest(uint32_t channel, std::string bytes, bool binary) {
  bool wake = false;
  {
    // One lock hold: two producers of the channel cannot both leave a frame queued.
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_ || finishing_) return;
    if (auto it = data_.find(channel); it != data_.end()) {
      for (const auto& f : it->second) bytes_ -= f.size();
      it->second.clear();
      channel_bytes_[channel] = 0;
    }
    PushDataLocked(channel, Frame{binary, std::move(bytes), nullptr, channel, 0}, &wake);
  }
  if (wake) cv_.notify_one();
}

bool SendQueue::PushDataLocked(uint32_t channel, Frame frame, bool* wake) {
  if (closed_ || finishing_) return false;
  const size_t size = frame.size();
  if (size > limit_) {
    ++drops_[channel];
    return false;
  }
  while (bytes_ + size > limit_) {
    // The channel holding the most bytes gives up its oldest frame (a scan of the channels).
    uint32_t busiest = 0;
    size_t most = 0;
    for (const auto& [c, b] : channel_bytes_)
      if (b > most) most = b, busiest = c;
    auto& q = data_[busiest];
    bytes_ -= q.front().size();
    channel_bytes_[busiest] -= q.front().size();
    q.pop_front();
    ++drops_[busiest];
  }
  bytes_ += size;
  channel_bytes_[channel] += size;
  frame.order = next_order_++;
  data_[channel].push_back(std::move(frame));
  *wake = consumer_idle_;
  consumer_idle_ = false;  // one wake-up is enough
  if (*wake) ++wakeups_by_producers_;
  return true;
}

bool SendQueue::PopAll(std::vector<Frame>* out) {
  out->clear();
  std::deque<std::string> control;
  std::map<uint32_t, std::deque<Frame>> data;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      if (closed_) return false;
      if (!control_.empty()) break;
      if (finishing_) {  // what is left goes at once; then the end
        if (HasData()) break;
        closed_ = true;
        return false;
      }
      const auto due = last_flush_ + flush_interval_;
      if (std::chrono::steady_clock::now() < due) {
        // The quiet time after a flush: data collects without waking anyone.
        cv_.wait_until(lock, due);
        continue;
      }
      if (HasData()) break;
      consumer_idle_ = true;  // the next push wakes us
      ++idle_waits_;
      cv_.wait(lock);
      consumer_idle_ = false;
    }
    last_flush_ = std::chrono::steady_clock::now();
    // Swaps, no copies: producers (graph threads) wait for this lock.
    control.swap(control_);
    control_bytes_ = 0;
    data.swap(data_);
    channel_bytes_.clear();
    bytes_ = 0;
  }
  for (auto& c : control) out->push_back(Frame{false, std::move(c), nullptr, 0, 0});
  // Data in push order across channels: the per-channel queues merged by `order`.
  const size_t first_data = out->size();
  for (auto& [c, q] : data)
    for (auto& f : q) out->push_back(std::move(f));
  std::sort(out->begin() + static_cast<std::ptrdiff_t>(first_data), out->end(),
            [](const Frame& a, const Frame& b) { return a.order < b.order; });
  return true;
}

uint64_t SendQueue::wakeups_by_producers() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return wakeups_by_producers_;
}

uint64_t SendQueue::idle_waits() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return idle_waits_;
}

bool SendQueue::HasData() const {
  for (const auto& [c, q] : data_)
    if (!q.empty()) return true;
  return false;
}

void SendQueue::Close() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
  }
  cv_.notify_all();
}

void SendQueue::Finish() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    finishing_ = true;
  }
  cv_.notify_all();
}

std::map<uint32_t, uint64_t> SendQueue::TakeDrops() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::map<uint32_t, uint64_t> out;
  out.swap(drops_);
  return out;
}

size_t SendQueue::queued_bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return bytes_;
}

}  // namespace dyad::web
