/// SendQueue — one WebSocket client's outgoing frames, bounded in bytes, never blocking the
/// producer (a graph component's Publish(), through the bridge's subscription callback).
///
/// Two kinds of frames: control frames (JSON: advertise, status, ...) are never dropped and are
/// sent first; data frames belong to a channel and are dropped when the buffer is full: past
/// `limit_bytes`, the oldest frames of the channel holding the most bytes are dropped until the
/// new frame fits (a big, busy topic cannot starve the small ones, foxglove_bridge's lesson).
/// Drops are counted per channel for the status message the sender reports.
///
/// Thread-safe: any number of producers, one consumer (the client's sender thread) blocking in
/// Pop(). Control frames and Close() wake the consumer at once; data frames are picked up within
/// kBatch (a producer never pays for waking the consumer).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace dyad::web {

struct Frame {
  bool binary = false;
  std::string bytes;
  uint32_t channel = 0;  // data frames: their channel; 0 for control frames
  uint64_t order = 0;    // push order (data frames leave in push order)
};

class SendQueue {
 public:
  explicit SendQueue(size_t limit_bytes) : limit_(limit_bytes) {}

  // Queues a control frame (never dropped).
  void PushControl(std::string json);
  // Queues a data frame of `channel`; drops the busiest channel's oldest frames to stay within
  // the limit. A frame larger than the whole limit is dropped itself. Returns false if dropped.
  bool PushData(uint32_t channel, std::string bytes, bool binary = true);
  // Queues a data frame that replaces any frame of `channel` still queued (newest only: a slow
  // page gets the latest robot state, never a backlog).
  void PushLatest(uint32_t channel, std::string bytes, bool binary = true);
  // Waits for the next frame; false once closed (frames still queued are discarded).
  bool Pop(Frame* out);
  void Close();

  // Drops per channel since the last call (and resets them).
  std::map<uint32_t, uint64_t> TakeDrops();
  size_t queued_bytes() const;

 private:
  static constexpr std::chrono::milliseconds kBatch{2};
  bool HasData() const;  // REQUIRES: mutex_ held
  const size_t limit_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  bool closed_ = false;
  uint64_t next_order_ = 0;
  size_t bytes_ = 0;  // data frames only
  std::deque<std::string> control_;
  std::map<uint32_t, std::deque<Frame>> data_;   // per channel, oldest first
  std::map<uint32_t, size_t> channel_bytes_;
  std::map<uint32_t, uint64_t> drops_;
};

}  // namespace dyad::web
