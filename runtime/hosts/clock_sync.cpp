#include "hosts/clock_sync.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <dyad/message_traits.hpp>

#include "exec/wall_clock.hpp"

namespace dyad {

ClockSync::ClockSync(const Graph& graph, std::string process, std::string host, std::function<void(const std::string&)> warn)
    : graph_(graph), process_(std::move(process)), host_(std::move(host)), warn_(std::move(warn)) {}

ClockSync::~ClockSync() { Stop(); }

Status ClockSync::Open(Transport* transport) {
  // Probes: best effort (a lost one is simply not an exchange), deep enough for every peer's answer.
  auto w = CreateRuntimeWriter(transport, runtime_topics::kClock);
  if (!w.ok()) return w.status();
  probe_writer_ = w.value();
  auto r = CreateRuntimeReader(transport, runtime_topics::kClock, [this] { OnProbes(); });
  if (!r.ok()) return r.status();
  probe_reader_ = r.value();
  auto o = CreateRuntimeWriter(transport, runtime_topics::kClockOffsets);
  if (!o.ok()) return o.status();
  offset_writer_ = o.value();
  return Status::OK();
}

void ClockSync::Start(double period_s) {
  thread_ = std::thread([this, period_s] {
    const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(period_s));
    auto next_ask = std::chrono::steady_clock::now();
    auto next_publish = next_ask + period / 2;  // half a period after asking, the answers are in
    UniqueLock lock(mutex_);
    while (!stop_) {
      cv_.wait_until(lock.native(), std::min(next_ask, next_publish), [&] {
        mutex_.AssertHeld();  // the wait calls its predicate with the lock held
        return stop_ || !to_answer_.empty();
      });
      if (stop_) break;
      std::vector<msg::ClockProbe> answers;
      answers.swap(to_answer_);
      lock.Unlock();
      for (auto& a : answers) {
        a.t3_ns(WallNowNs());
        a.header().stamp_ns(a.t3_ns());
        probe_writer_->Write(&a).IgnoreError();  // a lost answer is a lost sample: the peer probes again
      }
      const auto now = std::chrono::steady_clock::now();
      if (now >= next_ask) {
        Ask();
        next_ask += period;
      }
      if (now >= next_publish) {
        Publish();
        next_publish += period;
      }
      lock.Lock();
    }
  });
}

void ClockSync::Stop() {
  {
    MutexLock lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

// Writes happen outside mutex_ (a reader in this process gets the sample inside Write(), in
// OnProbes, which takes mutex_) and never from OnProbes: Fast DDS 2.9 holds the reader's lock
// during the callback, and a write there delivering to this process's own reader while another
// thread writes deadlocks the two (seen: a best-effort writer and reader, lock order inverted).
void ClockSync::Ask() {
  UniqueLock lock(mutex_);
  msg::ClockProbe p;
  p.graph_name(graph_.name);
  p.asker(process_);
  p.id(next_id_);
  // Requests older than the window are not waited for any more.
  while (!asked_.empty() && asked_.begin()->first + kWindow < next_id_) asked_.erase(asked_.begin());
  p.header().source("dyad/" + process_);
  p.header().sequence_number(++probe_sequence_);
  const int64_t t1 = WallNowNs();
  p.header().stamp_ns(t1);
  p.t1_ns(t1);
  asked_[next_id_++] = t1;
  lock.Unlock();
  probe_writer_->Write(&p).IgnoreError();  // a lost probe: the next period probes again
}

void ClockSync::OnProbes() {
  const int64_t received = WallNowNs();  // t2 or t4: before anything else
  UniqueLock lock(mutex_);
  const size_t answers_before = to_answer_.size();
  msg::ClockProbe p;
  while (probe_reader_->TakeNext(&p)) {
    if (p.graph_name() != graph_.name) continue;
    if (p.answerer().empty() && p.asker() != process_) {  // a request: answer it
      p.answerer(process_);
      p.t2_ns(received);
      p.header().source("dyad/" + process_);
      p.header().sequence_number(++probe_sequence_);
      to_answer_.push_back(p);
    } else if (p.asker() == process_ && !p.answerer().empty() && p.answerer() != process_) {  // an answer to us
      auto it = asked_.find(p.id());
      if (it == asked_.end() || it->second != p.t1_ns()) continue;
      const int64_t t1 = p.t1_ns(), t2 = p.t2_ns(), t3 = p.t3_ns(), t4 = received;
      Peer& peer = peers_[p.answerer()];
      peer.last_answered = p.id();
      peer.window.push_back({((t2 - t1) + (t3 - t4)) / 2, (t4 - t1) - (t3 - t2)});
      if (peer.window.size() > kWindow) peer.window.pop_front();
    }
  }
  const bool wake = to_answer_.size() > answers_before;
  lock.Unlock();
  if (wake) cv_.notify_all();
}

std::vector<msg::ClockOffset> ClockSync::Offsets() const {
  MutexLock lock(mutex_);
  std::vector<msg::ClockOffset> out;
  for (const auto& [name, peer] : peers_) {
    // A peer that has not answered the last kWindow requests is gone: its offset is stale.
    if (peer.window.empty() || peer.last_answered + kWindow < next_id_) continue;
    const Exchange best = *std::min_element(peer.window.begin(), peer.window.end(),
                                            [](const Exchange& a, const Exchange& b) { return a.round_trip_ns < b.round_trip_ns; });
    msg::ClockOffset o;
    o.graph_name(graph_.name);
    o.process_name(process_);
    o.host(host_);
    o.peer_process(name);
    if (const ProcessConfig* pc = graph_.FindProcess(name)) o.peer_host(pc->host);
    o.offset_ns(best.offset_ns);
    o.round_trip_ns(best.round_trip_ns);
    out.push_back(o);
  }
  return out;
}

void ClockSync::Publish() {
  const double bound_ms = graph_.network.max_clock_offset_ms;
  for (msg::ClockOffset o : Offsets()) {
    UniqueLock lock(mutex_);
    o.header().source("dyad/" + process_);
    o.header().sequence_number(++offset_sequence_);
    o.header().stamp_ns(WallNowNs());
    Peer& peer = peers_[o.peer_process()];
    const double offset_ms = o.offset_ns() * 1e-6;
    if (std::abs(offset_ms) > bound_ms && !peer.warned && warn_) {
      char text[512];
      std::snprintf(text, sizeof(text),
                    "the clock of process '%s' is %+.3f ms off this one's (round trip %.3f ms; bound: "
                    "network.max_clock_offset_ms = %g): stamps across them disagree by that much; sync the hosts' "
                    "clocks (chrony, docs/distributed.md)",
                    o.peer_process().c_str(), offset_ms, o.round_trip_ns() * 1e-6, bound_ms);
      warn_(text);
    }
    peer.warned = std::abs(offset_ms) > bound_ms;
    lock.Unlock();
    offset_writer_->Write(&o).IgnoreError();  // reported again each period
  }
}

}  // namespace dyad
