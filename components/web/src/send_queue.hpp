/// SendQueue — one WebSocket client's outgoing frames, bounded in bytes, never blocking the
/// producer (a graph component's Publish(), through the bridge's subscription callback).
///
/// Two kinds of frames: control frames (JSON: advertise, status, ...) are never dropped and are
/// sent first, so they cannot be shed either: control frames past `limit_bytes` of their own (a
/// client that sends requests and never reads the answers) close the queue as overflowed, and
/// the server disconnects that client. Data frames belong to a channel and are dropped when the buffer is full: past
/// `limit_bytes`, the oldest frames of the channel holding the most bytes are dropped until the
/// new frame fits (a big, busy topic cannot starve the small ones, foxglove_bridge's lesson).
/// Drops are counted per channel for the status message the sender reports.
///
/// Waking the consumer. A producer is a graph thread in the middle of a step: waking a sender
/// thread per sample made the sender preempt the graph on a two-core machine. So data is handed
/// out in batches, at most once per `flush_interval`: a stream faster than that is collected by
/// the consumer's own timer and its producers never wake anyone; the first sample after a quiet
/// spell (a sparse stream, a page's 30 Hz robot state) wakes the consumer at once. An idle
/// client's consumer sleeps until there is something to send (no polling). Control frames and
/// Close() always wake it at once.
///
/// Memory: at most `limit_bytes` of data and `limit_bytes` of control frames queued, plus the batch the consumer is writing. Work under the
/// queue's mutex: a push that fits is O(log channels) (per-channel maps); a push past the limit
/// also scans the channels once per frame it drops, to find the busiest (channels number tens);
/// PushLatest frees the frames it replaces; the consumer takes a batch by swapping the queues and
/// clears the per-channel byte counts (O(channels)). Merging a batch into push order happens
/// after the lock is released.
///
/// Thread-safe: any number of producers, one consumer (the client's sender thread) blocking in
/// PopAll().
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace dyad::web {

struct Frame {
  bool binary = false;
  std::string bytes;                        // the frame, or its head when `tail` is set
  std::shared_ptr<const std::string> tail;  // appended to `bytes`: one sample shared by every client's frame
  uint32_t channel = 0;                     // data frames: their channel; 0 for control frames
  uint64_t order = 0;                       // push order (data frames leave in push order)
  size_t size() const { return bytes.size() + (tail ? tail->size() : 0); }
};

class SendQueue {
 public:
  // One 60 Hz display frame: what a viewer cannot tell from "at once". Zero: every sample that
  // finds the consumer idle wakes it (the subject's page, whose robot state is a person's feedback).
  static constexpr std::chrono::milliseconds kDefaultFlushInterval{16};

  explicit SendQueue(size_t limit_bytes, std::chrono::steady_clock::duration flush_interval = kDefaultFlushInterval)
      : limit_(limit_bytes), flush_interval_(flush_interval) {}

  // Queues a control frame (never dropped); past the control limit, closes the queue as
  // overflowed instead and returns false.
  bool PushControl(std::string json);
  // Queues a data frame of `channel` (`bytes` followed by `tail`, when given); drops the busiest
  // channel's oldest frames to stay within the limit. A frame larger than the whole limit is
  // dropped itself. Returns false if dropped.
  bool PushData(uint32_t channel, std::string bytes, bool binary = true, std::shared_ptr<const std::string> tail = nullptr);
  // Queues a data frame that replaces any frame of `channel` still queued (newest only: a slow
  // page gets the latest robot state, never a backlog). Atomic: whatever the producers, at most
  // one frame of `channel` is queued after each call. Replaced frames are not counted as drops.
  void PushLatest(uint32_t channel, std::string bytes, bool binary = true);
  // Waits until there is something to send (see "Waking the consumer"), then moves every queued
  // frame to `out` (replacing its contents): control frames first, then data in push order.
  // False once closed (frames still queued are discarded), or finished with nothing left.
  bool PopAll(std::vector<Frame>* out);
  void Close();
  // Closes after what is queued: pushes are refused from now on, PopAll hands out the frames
  // still queued at once (no flush interval) and then returns false.
  void Finish();
  // Whether PushControl closed the queue (the client's fault, not the server's).
  bool overflowed() const;

  // Drops per channel since the last call (and resets them).
  std::map<uint32_t, uint64_t> TakeDrops();
  size_t queued_bytes() const;
  // How often a data push woke the consumer, and how often the consumer went idle (waiting for
  // a push): what the wake-up policy promises, made visible (tests).
  uint64_t wakeups_by_producers() const;
  uint64_t idle_waits() const;

 private:
  bool HasData() const;  // REQUIRES: mutex_ held
  // PushData's work; sets *wake when the consumer must be notified. REQUIRES: mutex_ held.
  bool PushDataLocked(uint32_t channel, Frame frame, bool* wake);
  const size_t limit_;
  const std::chrono::steady_clock::duration flush_interval_;
  mutable std::mutex mutex_;
  std::condition_variable cv_;
  bool closed_ = false, overflowed_ = false, finishing_ = false;
  size_t control_bytes_ = 0;
  bool consumer_idle_ = false;  // the consumer waits with nothing queued: the next push wakes it
  uint64_t wakeups_by_producers_ = 0, idle_waits_ = 0;
  // min(), not the epoch: steady_clock's zero is boot time, and a machine up for less than one
  // interval would hold the first batch back.
  std::chrono::steady_clock::time_point last_flush_ = std::chrono::steady_clock::time_point::min();
  uint64_t next_order_ = 0;
  size_t bytes_ = 0;  // data frames only
  std::deque<std::string> control_;
  std::map<uint32_t, std::deque<Frame>> data_;   // per channel, oldest first
  std::map<uint32_t, size_t> channel_bytes_;
  std::map<uint32_t, uint64_t> drops_;
};

}  // namespace dyad::web
