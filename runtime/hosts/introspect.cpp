#include "dyad/introspect.hpp"

#include <dyad/ros2_names.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <iomanip>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <ostream>
#include <set>
#include <sstream>
#include <thread>


#include <dyad/message_traits.hpp>
#include <dyad/msg/types.hpp>

#include "hosts/clock_sync.hpp"
#include "dds/dds_participant.hpp"
#include "graph/graph_topics.hpp"
#include "graph/network_scope.hpp"
#include "hosts/start_barrier.hpp"
#include "hosts/watcher_join.hpp"
#include "dyad/interrupt.hpp"

namespace dyad {
namespace {

using Steady = std::chrono::steady_clock;

std::unique_ptr<DdsParticipant> Join(const IntrospectOptions& o, std::ostream& err) {
  return JoinAsWatcher(o, "dyad/introspect", err);
}

// Appended where a watcher found nothing: a local watcher (no --graph, or a local graph's) reaches
// this machine only (graph/network_scope.hpp).
std::string ScopeNote(const IntrospectOptions& o) {
  const std::string local = LocalScopeNote(o.network, /*watcher=*/true);
  return local.empty() ? "" : "; " + local;
}

// A watcher's reader: the participant's serialized subscription (BEST_EFFORT: it matches every
// writer and never makes one wait), feeding a bounded queue that this thread drains. A watcher
// is a guest: when it falls behind, the oldest samples are dropped, not the graph slowed.
class RawReader {
 public:
  RawReader(DdsParticipant& p, const TypeInfo& type, const std::string& topic) {
    auto r = p.CreateSerializedReader(topic, type, TopicQos{Reliability::kBestEffort, kDepth, 0, false}, &clock_,
                                      [this](const SerializedSample& s) { Push(s.cdr); });
    ok_ = r.ok();
  }
  bool ok() const { return ok_; }
  // Next sample, serialised; false when none is waiting.
  bool Next(std::vector<uint8_t>* bytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (queue_.empty()) return false;
    *bytes = std::move(queue_.front());
    queue_.pop_front();
    return true;
  }
  // Waits up to `seconds` for a sample; true when one is waiting.
  bool Wait(double seconds) {
    std::unique_lock<std::mutex> lock(mutex_);
    return cv_.wait_for(lock, std::chrono::duration<double>(seconds), [&] { return !queue_.empty(); });
  }

 private:
  static constexpr int kDepth = 100;
  class WallClock final : public Clock {
   public:
    int64_t now_ns() const override {
      return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
    }
  };
  void Push(std::span<const uint8_t> cdr) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (queue_.size() >= static_cast<size_t>(kDepth)) queue_.pop_front();
      queue_.emplace_back(cdr.begin(), cdr.end());
    }
    cv_.notify_one();
  }
  WallClock clock_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::vector<uint8_t>> queue_;
  bool ok_ = false;
};

// A participant reading one topic of a running graph, with the type its writers use.
// The reader is declared first, so the participant (which owns the subscription calling into
// the reader) is destroyed before it.
struct TopicTap {
  std::unique_ptr<RawReader> reader;
  std::unique_ptr<DdsParticipant> participant;
  const TypeInfo* type = nullptr;
};

// Joins the domain, waits for a writer of `topic`, resolves its type and opens a reader;
// nullopt (after saying why on `err`) when any of that fails.
std::optional<TopicTap> Tap(const IntrospectOptions& o, const Catalog& catalog, const std::string& topic, std::ostream& err,
                            const InterruptWatcher& interrupt) {
  TopicTap tap;
  tap.participant = Join(o, err);
  if (!tap.participant) return std::nullopt;
  const std::string dds_type = DiscoverType(*tap.participant, topic, o.wait_s, interrupt);
  if (interrupt.interrupted()) return std::nullopt;
  if (dds_type.empty()) {
    err << "no writer of topic '" << topic << "' found on domain " << o.domain_id << " within " << o.wait_s << " s"
        << ScopeNote(o) << "\n";
    return std::nullopt;
  }
  tap.type = ResolveType(catalog, dds_type, topic, err);
  if (tap.type == nullptr) return std::nullopt;
  tap.reader = std::make_unique<RawReader>(*tap.participant, *tap.type, topic);
  if (!tap.reader->ok()) {
    err << "cannot create a reader on '" << topic << "'\n";
    return std::nullopt;
  }
  return tap;
}

// `dyad status --graph`: every process heard; the step statistics of every component of the
// running ones; the offsets between every two processes running for 3 s (measured every 2 s).
bool HeardAll(const Graph& graph, const std::map<std::string, msg::ProcessState>& procs,
              const std::map<std::string, msg::ComponentStats>& components,
              const std::map<std::pair<std::string, std::string>, msg::ClockOffset>& clock) {
  const int64_t now_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  std::vector<std::string> settled;  // running for 3 s: they have measured each other
  for (const std::string& process : graph.ProcessNames()) {
    auto it = procs.find(graph.name + "/" + process);
    if (it == procs.end()) return false;
    if (it->second.state() != "running") continue;
    for (const auto& c : graph.components)
      if (graph.ProcessOf(c) == process && !components.count(process + "/" + c.name)) return false;
    if (it->second.start_ns() > 0 && now_ns - it->second.start_ns() > 3'000'000'000) settled.push_back(process);
  }
  for (const auto& a : settled)
    for (const auto& b : settled)
      if (a != b && !clock.count({a, b})) return false;
  return true;
}

// `dyad topics --graph`: every topic the components bind has a writer (if one writes it) and a
// reader (if one reads it), and every process's participant was discovered.
bool DiscoveredAll(const Graph& graph, const std::vector<DiscoveredEndpoint>& found) {
  std::set<std::pair<std::string, bool>> seen;  // (topic, writer)
  std::set<std::string> participants;
  for (const auto& e : found) seen.insert({e.topic, e.writer}), participants.insert(e.participant);
  // A watcher sees a ROS 2 topic under its ROS 2 name.
  auto seen_as = [&](const std::string& topic, bool writer) {
    const TopicConfig* t = graph.FindTopic(topic);
    return seen.count({t && !t->ros2.empty() ? t->ros2 : topic, writer}) > 0;
  };
  for (const auto& c : graph.components) {
    for (const auto& port : c.outputs)
      if (!port.topic.empty() && !seen_as(port.topic, true)) return false;
    for (const auto& port : c.inputs)
      if (!port.topic.empty() && !seen_as(port.topic, false)) return false;
  }
  for (const std::string& process : graph.ProcessNames()) {
    const std::string suffix = "/" + graph.name + "/" + process;
    if (std::none_of(participants.begin(), participants.end(), [&](const std::string& name) {
          return name.size() >= suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
        }))
      return false;
  }
  return true;
}

}  // namespace

int ListTopics(const IntrospectOptions& o, std::ostream& out, const Graph* graph) {
  InterruptWatcher interrupt;  // before the participant: its threads inherit the blocked signals
  auto p = Join(o, out);
  if (!p) return 1;
  Steady::time_point end = Steady::now() + std::chrono::duration_cast<Steady::duration>(std::chrono::duration<double>(o.wait_s));
  while (Steady::now() < end && !interrupt.interrupted()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    // The rest of that discovery burst (another reader of a topic) comes within a moment.
    if (graph && DiscoveredAll(*graph, p->Discovered())) end = std::min(end, Steady::now() + std::chrono::milliseconds(200));
  }
  if (interrupt.interrupted()) return 0;
  struct Row {
    std::set<std::string> types, participants;
    int writers = 0, readers = 0;
  };
  std::map<std::string, Row> rows;
  for (const auto& e : p->Discovered()) {
    if (e.participant == p->name()) continue;
    Row& r = rows[e.topic];
    const std::string ros2_type = Ros2TypeOfDdsType(e.type);  // a ROS 2 type by its ROS 2 name
    r.types.insert(ros2_type.empty() ? e.type : ros2_type);
    r.participants.insert(e.participant);
    (e.writer ? r.writers : r.readers)++;
  }
  for (const auto& [topic, r] : rows) {
    out << topic << "  ";
    for (const auto& t : r.types) out << t << (r.types.size() > 1 ? " " : "");
    out << "  writers=" << r.writers << " readers=" << r.readers << "  [";
    bool first = true;
    for (const auto& pp : r.participants) out << (first ? "" : ", ") << pp, first = false;
    out << "]" << (r.types.size() > 1 ? "  TYPE MISMATCH" : "") << "\n";
  }
  if (rows.empty()) {
    std::cerr << "dyad topics: no endpoint discovered on domain " << o.domain_id << " within " << o.wait_s
              << " s (a longer --wait helps on a loaded machine or network; a stepped run, clock: stepped, is"
                 " private to its process and never seen here)"
              << ScopeNote(o) << "\n";
    return 1;
  }
  return 0;
}

int DiscoverLiveGraph(const IntrospectOptions& o, const Catalog& catalog, const Graph* graph, double listen_s, LiveGraph* live,
                      std::ostream& err) {
  InterruptWatcher interrupt;  // before the participant: its threads inherit the blocked signals
  // Before the participant, so that it (whose subscriptions call into them) goes first.
  std::vector<std::pair<std::string, std::unique_ptr<RawReader>>> readers;
  auto p = Join(o, err);
  if (!p) return 1;
  Steady::time_point end = Steady::now() + std::chrono::duration_cast<Steady::duration>(std::chrono::duration<double>(o.wait_s));
  while (Steady::now() < end && !interrupt.interrupted()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (graph && DiscoveredAll(*graph, p->Discovered())) end = std::min(end, Steady::now() + std::chrono::milliseconds(200));
  }
  std::map<std::string, std::string> types;  // topic -> a writer's type
  for (const auto& e : p->Discovered()) {
    if (e.participant == p->name() || e.topic.rfind("dyad/", 0) == 0) continue;
    live->endpoints.push_back({e.participant, e.topic, e.type, e.writer});
    if (e.writer) types.emplace(e.topic, e.type);
  }
  if (live->endpoints.empty()) {
    err << "dyad graph --live: no endpoint discovered on domain " << o.domain_id << " within " << o.wait_s
        << " s (a stepped run is private to its process and never seen here)" << ScopeNote(o) << "\n";
    return 1;
  }
  // Rates: one reader per written topic of a known type, counting for listen_s.
  std::ostringstream unknown;  // types this dyad does not know: no rate, said once
  for (const auto& [topic, dds_type] : types)
    if (const TypeInfo* type = ResolveType(catalog, dds_type, topic, unknown))
      readers.emplace_back(topic, std::make_unique<RawReader>(*p, *type, topic));
  std::map<std::string, uint64_t> counts;
  const auto listen_end = Steady::now() + std::chrono::duration_cast<Steady::duration>(std::chrono::duration<double>(listen_s));
  std::vector<uint8_t> bytes;
  while (Steady::now() < listen_end && !interrupt.interrupted()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    for (auto& [topic, reader] : readers)
      while (reader->Next(&bytes)) ++counts[topic];
  }
  for (const auto& [topic, reader] : readers) live->rates_hz[topic] = static_cast<double>(counts[topic]) / std::max(listen_s, 1e-3);
  return 0;
}

int EchoTopic(const IntrospectOptions& o, const Catalog& catalog, const std::string& topic, uint64_t count, double duration_s,
              const SamplePrinter& printer, std::ostream& out, std::ostream& err) {
  InterruptWatcher interrupt;  // before the participant: its threads inherit the blocked signals
  auto tap = Tap(o, catalog, topic, err, interrupt);
  if (interrupt.interrupted()) return 0;
  if (!tap) return 1;
  const TypeInfo* type = tap->type;
  RawReader& reader = *tap->reader;
  const auto end = duration_s > 0 ? Steady::now() + std::chrono::duration<double>(duration_s) : Steady::time_point::max();
  uint64_t n = 0;
  std::vector<uint8_t> bytes;
  while (!interrupt.interrupted() && Steady::now() < end && (count == 0 || n < count)) {
    reader.Wait(0.1);
    while (reader.Next(&bytes)) {
      out << printer(*type, bytes.data(), bytes.size()) << "\n" << std::flush;
      if (!out) return 0;  // the reader of our output went away (`| head`): done, quietly
      if (count != 0 && ++n >= count) break;
    }
  }
  return 0;
}

int TopicHz(const IntrospectOptions& o, const Catalog& catalog, const std::string& topic, double duration_s, std::ostream& out,
            std::ostream& err) {
  InterruptWatcher interrupt;  // before the participant: its threads inherit the blocked signals
  auto tap = Tap(o, catalog, topic, err, interrupt);
  if (interrupt.interrupted()) return 0;
  if (!tap) return 1;
  RawReader& reader = *tap->reader;
  const auto start = Steady::now();
  const auto end = duration_s > 0 ? start + std::chrono::duration<double>(duration_s) : Steady::time_point::max();
  auto next_report = start + std::chrono::seconds(1);
  std::vector<double> periods;
  Steady::time_point last{};
  uint64_t total = 0;
  std::vector<uint8_t> bytes;
  while (!interrupt.interrupted() && Steady::now() < end) {
    reader.Wait(0.05);
    while (reader.Next(&bytes)) {
      const auto now = Steady::now();
      if (last != Steady::time_point{}) periods.push_back(std::chrono::duration<double>(now - last).count());
      last = now;
      ++total;
    }
    if (Steady::now() >= next_report) {
      next_report += std::chrono::seconds(1);
      if (periods.empty()) {
        out << "no new samples\n";
        continue;
      }
      double sum = 0;
      for (double d : periods) sum += d;
      const double mean = sum / static_cast<double>(periods.size());
      out << std::fixed << std::setprecision(3) << "rate " << 1.0 / mean << " Hz  period mean " << mean * 1e3 << " ms  min "
          << *std::min_element(periods.begin(), periods.end()) * 1e3 << " ms  max "
          << *std::max_element(periods.begin(), periods.end()) * 1e3 << " ms  samples " << total << "\n"
          << std::flush;
      if (!out) return 0;  // the reader of our output went away
      out.unsetf(std::ios::fixed);
      periods.clear();
    }
  }
  return total == 0 ? 1 : 0;
}

int ShowStatus(const IntrospectOptions& o, const Graph* graph, std::ostream& out, std::ostream& err) {
  const std::string graph_name = graph ? graph->name : "";
  InterruptWatcher interrupt;  // before the participant: its threads inherit the blocked signals
  auto p = Join(o, err);
  if (!p) return 1;
  // dyad/processes is RELIABLE + TRANSIENT_LOCAL with one sample per writer: a reliable reader
  // gets each process's last state at once and can never make a writer wait (its history is 1).
  auto processes = CreateRuntimeReader(p.get(), runtime_topics::kProcesses, nullptr, /*watcher=*/true);
  auto stats = CreateRuntimeReader(p.get(), runtime_topics::kStats, nullptr, /*watcher=*/true);
  auto offsets = CreateRuntimeReader(p.get(), runtime_topics::kClockOffsets, nullptr, /*watcher=*/true);
  if (!processes.ok() || !stats.ok() || !offsets.ok()) {
    err << "dyad status: cannot create its readers\n";
    return 1;
  }
  std::map<std::string, msg::ProcessState> procs;             // "graph/process" -> newest
  std::map<std::string, msg::ComponentStats> components;      // "process/component" -> newest
  std::map<std::pair<std::string, std::string>, msg::ClockOffset> clock;  // (measurer, peer) -> newest
  Steady::time_point end = Steady::now() + std::chrono::duration_cast<Steady::duration>(std::chrono::duration<double>(o.wait_s));
  while (Steady::now() < end && !interrupt.interrupted()) {
    // Heard all: the rest of the late joiner's burst (the offsets beside the stats) comes within a moment.
    if (graph && HeardAll(*graph, procs, components, clock)) end = std::min(end, Steady::now() + std::chrono::milliseconds(150));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    msg::ProcessState ps;
    while (processes.value()->TakeNext(&ps))
      if (graph_name.empty() || ps.graph_name() == graph_name) procs[ps.graph_name() + "/" + ps.process_name()] = ps;
    msg::ComponentStats cs;
    while (stats.value()->TakeNext(&cs)) components[cs.process_name() + "/" + cs.component_name()] = cs;
    msg::ClockOffset co;
    while (offsets.value()->TakeNext(&co))
      if (graph_name.empty() || co.graph_name() == graph_name) clock[{co.process_name(), co.peer_process()}] = co;
  }
  if (procs.empty()) {
    err << "dyad status: no process" << (graph_name.empty() ? "" : " of graph '" + graph_name + "'") << " heard on domain "
        << o.domain_id << " within " << o.wait_s << " s" << ScopeNote(o) << "\n";
    return 1;
  }
  std::set<std::string> process_names;
  out << std::left << std::setw(24) << "process" << std::setw(16) << "host" << std::setw(9) << "pid" << std::setw(10) << "state"
      << std::setw(10) << "restarts" << std::setw(10) << "renewals" << "running for\n";
  const int64_t now_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  for (const auto& [key, ps] : procs) {
    process_names.insert(ps.process_name());
    std::ostringstream running;
    if (ps.start_ns() > 0 && ps.state() == "running")
      running << std::fixed << std::setprecision(1) << (now_ns - ps.start_ns()) * 1e-9 << " s";
    out << std::left << std::setw(24) << key << std::setw(16) << ps.host() << std::setw(9) << ps.pid() << std::setw(10) << ps.state()
        << std::setw(10) << ps.restarts() << std::setw(10) << ps.renewals() << running.str() << "\n";
  }
  out << "\nclock offsets (the peer's clock minus the measuring process's, from the exchange with the least round trip):\n";
  if (clock.empty()) out << "  none measured yet (every 2 s once the graph runs)\n";
  for (const auto& [key, co] : clock)
    out << "  " << std::left << std::setw(16) << co.process_name() << "-> " << std::setw(16) << co.peer_process() << std::right
        << std::fixed << std::setprecision(3) << std::showpos << std::setw(10) << co.offset_ns() * 1e-6 << std::noshowpos
        << " ms  round trip " << co.round_trip_ns() * 1e-6 << " ms\n";
  out.unsetf(std::ios::fixed);
  out << "\n" << std::left << std::setw(20) << "component" << std::setw(16) << "process" << std::right << std::setw(9) << "steps"
      << std::setw(11) << "mean_ms" << std::setw(11) << "p99_ms" << std::setw(11) << "max_ms" << std::setw(8) << "misses\n";
  out << std::fixed << std::setprecision(3);
  for (const auto& [key, cs] : components) {
    if (!process_names.count(cs.process_name())) continue;
    out << std::left << std::setw(20) << cs.component_name() << std::setw(16) << cs.process_name() << std::right << std::setw(9)
        << cs.steps() << std::setw(11) << cs.step_mean_s() * 1e3 << std::setw(11) << cs.step_p99_s() * 1e3 << std::setw(11)
        << cs.step_max_s() * 1e3 << std::setw(7) << cs.deadline_misses() << "\n";
  }
  out.unsetf(std::ios::fixed);
  return 0;
}

}  // namespace dyad
