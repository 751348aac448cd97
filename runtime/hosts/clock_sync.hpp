// ClockSync — each process of a multi-process wall-clock graph measures every other process's
// clock offset and round trip (internal to the runtime; docs/distributed.md, "Clocks").
//
// Samples carry their writer's wall-clock stamp; across hosts a stamp is only as good as the
// hosts' clock sync. So every `period` each process asks on dyad/clock (t1, its clock); every
// other process notes the receive time on the delivering thread (t2) and answers from its
// clock-sync thread with it and the send time (t3); the asker notes t4 on receipt and computes,
// as NTP does,
//   offset = ((t2 - t1) + (t3 - t4)) / 2      (the peer's clock minus ours)
//   round trip = (t4 - t1) - (t3 - t2)
// and keeps, per peer, the offset of the exchange with the least round trip among the last
// kWindow (queueing delays only ever add to the round trip and skew the offset). Each round's
// offsets are published on dyad/clock_offsets (the recorder keeps them; `dyad status` shows
// them; `dyad analyze` can correct stamps with them), and an offset beyond `warn_ms` is said
// through `warn` (once per peer until it is back within the bound).
//
// Accuracy: half the round-trip asymmetry, ~0.05 ms over loopback or a quiet LAN.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <dyad/graph.hpp>
#include <dyad/msg/types.hpp>
#include <dyad/status.hpp>
#include <dyad/thread_annotations.hpp>

#include "dds/transport.hpp"

namespace dyad {


class ClockSync {
 public:
  static constexpr int kWindow = 8;

  ClockSync(const Graph& graph, std::string process, std::string host, std::function<void(const std::string&)> warn);
  ~ClockSync();  // stops the thread; call Stop() first when the transport goes away before this

  // Creates the endpoints on `transport` (which must outlive Stop()).
  Status Open(Transport* transport);
  // Asks every `period_s`, from a thread of its own.
  void Start(double period_s);
  void Stop();

  // The newest offsets measured from this process (one per peer heard from).
  std::vector<msg::ClockOffset> Offsets() const;

 private:
  struct Exchange {
    int64_t offset_ns, round_trip_ns;
  };
  struct Peer {
    std::string host;
    std::deque<Exchange> window;
    uint64_t last_answered = 0;  // id of the newest request it answered
    bool warned = false;
  };
  void OnProbes() EXCLUDES(mutex_);  // the dyad/clock reader's callback: takes, notes t2/t4, never writes
  void Ask() EXCLUDES(mutex_);
  void Publish() EXCLUDES(mutex_);

  const Graph& graph_;
  std::string process_, host_;
  std::function<void(const std::string&)> warn_;
  TypedWriter* probe_writer_ = nullptr;
  TypedReader* probe_reader_ = nullptr;
  TypedWriter* offset_writer_ = nullptr;
  // Guards everything below. The writers are written outside it (clock_sync.cpp, Ask()); the
  // probe reader is taken from under it.
  mutable Mutex mutex_;
  uint64_t next_id_ GUARDED_BY(mutex_) = 1;
  uint64_t probe_sequence_ GUARDED_BY(mutex_) = 0;
  uint64_t offset_sequence_ GUARDED_BY(mutex_) = 0;
  std::map<uint64_t, int64_t> asked_ GUARDED_BY(mutex_);       // request id -> t1
  std::map<std::string, Peer> peers_ GUARDED_BY(mutex_);       // process -> what we measured
  std::vector<msg::ClockProbe> to_answer_ GUARDED_BY(mutex_);  // requests received, answered by the thread
  std::condition_variable cv_;
  bool stop_ GUARDED_BY(mutex_) = false;
  std::thread thread_;
};

}  // namespace dyad
