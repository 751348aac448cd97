#include "hosts/start_barrier.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <set>
#include <thread>

#include <cstdio>

#include <dyad/message_traits.hpp>

#include "graph/network_scope.hpp"

namespace dyad {

bool StartBarrier::Required(const std::string& process) const {
  const ProcessConfig* pc = graph_.FindProcess(process);
  return pc == nullptr || pc->required;
}

bool StartBarrier::Awaited(const std::string& process) const { return process == process_ || Required(process); }

StartBarrier::StartBarrier(const Graph& graph, std::string process, std::string host, uint32_t restarts)
    : graph_(graph), process_(std::move(process)), host_(std::move(host)), restarts_(restarts) {
  for (const auto& c : graph.components) {
    if (!Awaited(graph.ProcessOf(c))) continue;
    for (const auto& b : c.outputs) ++writers_of_[b.topic];
    for (const auto& b : c.inputs) ++readers_of_[b.topic];
  }
}

Status StartBarrier::Open(Transport* transport) {
  transport_ = transport;
  // Depth: the newest announcement of each writer is what counts; a few more absorb a burst.
  auto w = CreateRuntimeWriter(transport, runtime_topics::kProcesses);
  if (!w.ok()) return w.status();
  writer_ = w.value();
  auto r = CreateRuntimeReader(transport, runtime_topics::kProcesses);
  if (!r.ok()) return r.status();
  reader_ = r.value();
  return Status::OK();
}

void StartBarrier::Announce(const std::string& state) {
  if (writer_ == nullptr) return;
  msg::ProcessState m;
  m.header().source("dyad/" + process_);
  m.header().sequence_number(++sequence_);
  m.header().stamp_ns(WallNowNs());
  m.graph_name(graph_.name);
  m.process_name(process_);
  m.host(host_);
  m.pid(static_cast<int32_t>(getpid()));
  m.state(state);
  m.ready_ns(ready_ns_);
  m.start_ns(start_ns_);
  m.restarts(restarts_);
  m.renewals(renewals_);
  writer_->Write(&m).IgnoreError();  // best effort: a lost announcement is repeated with the next change
}

void StartBarrier::TakeAnnouncements() {
  msg::ProcessState m;
  while (reader_->TakeNext(&m))
    if (m.graph_name() == graph_.name) {
      heard_[m.process_name()] = m;
      heard_at_[m.process_name()] = std::chrono::steady_clock::now();
    }
}

std::string StartBarrier::MissingEndpoints(const std::vector<EndpointMatch>& matches) const {
  std::string out;
  for (const auto& e : matches) {
    if (e.topic.rfind("dyad/", 0) == 0 || (e.writer && e.serialized)) continue;
    const auto& expected_of = e.writer ? readers_of_ : writers_of_;
    const auto it = expected_of.find(e.topic);
    const int expected = it == expected_of.end() ? 0 : it->second;
    if (e.matched < expected)
      out += std::string(out.empty() ? "" : "; ") + "the " + (e.writer ? "writer" : "reader") + " of '" + e.topic +
             "' matched " + std::to_string(e.matched) + " of " + std::to_string(expected) + (e.writer ? " readers" : " writers");
  }
  return out;
}

std::set<std::string> StartBarrier::AwaitedProcesses() const {
  std::set<std::string> processes;
  for (const auto& c : graph_.components)
    if (Awaited(graph_.ProcessOf(c))) processes.insert(graph_.ProcessOf(c));
  return processes;
}

std::string StartBarrier::NotReady(int64_t* last_ready) const {
  std::string not_heard;
  for (const auto& p : AwaitedProcesses()) {
    const auto it = heard_.find(p);
    if (p == process_) continue;
    const int64_t ready = it == heard_.end() ? 0 : it->second.ready_ns();
    if (ready == 0)
      not_heard += std::string(not_heard.empty() ? "" : ", ") + "'" + p + "'" +
                   (it == heard_.end()                   ? " (not seen)"
                    : it->second.state() == "activating" ? " (still activating: a component's Activate waits, e.g. the web "
                                                           "component's wait_for_subject_s)"
                                                         : " (seen, its endpoints not all matched)");
    *last_ready = std::max(*last_ready, ready);
  }
  return not_heard;
}

Status StartBarrier::TimedOut(const std::string& not_heard, const std::string& missing_endpoints) const {
  std::string what;
  if (!not_heard.empty()) what = "processes not ready: " + not_heard;
  if (!missing_endpoints.empty()) what += std::string(what.empty() ? "" : "; ") + "here: " + missing_endpoints;
  // A process never heard from, in a graph that reaches this machine only: say so, and how to open it.
  if (const std::string local = LocalScopeNote(graph_.network);
      !local.empty() && not_heard.find("(not seen)") != std::string::npos)
    what += "; " + local;
  char waited[32];
  std::snprintf(waited, sizeof waited, "%g", graph_.network.start_timeout_s);  // 0.5 s, not "0 s"
  return Status::FailedPrecondition("process '" + process_ + "' waited " + waited +
                                    " s (network.start_timeout_s) for the graph to start together: " + what);
}

Status StartBarrier::WaitMatched(const std::function<bool()>& stopping) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(graph_.network.start_timeout_s);
  Announce("waiting");
  for (;;) {
    if (stopping()) return Status::OK();
    const std::string missing = MissingEndpoints(transport_->Matches());
    if (missing.empty()) break;
    if (std::chrono::steady_clock::now() >= deadline) {
      TakeAnnouncements();
      int64_t last_ready = 0;
      return TimedOut(NotReady(&last_ready), missing);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  Announce("activating");
  return Status::OK();
}

StatusOr<int64_t> StartBarrier::Wait(const std::function<bool()>& stopping) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(graph_.network.start_timeout_s);
  Announce("waiting");
  for (;;) {
    if (stopping()) return int64_t{0};
    TakeAnnouncements();
    const std::string missing_endpoints = MissingEndpoints(transport_->Matches());
    if (ready_ns_ == 0 && missing_endpoints.empty()) {
      ready_ns_ = WallNowNs();
      Announce("waiting");
    }
    // Joining a graph that already runs (restarted, or started late): no one waits for us.
    int64_t running_since = 0;  // the graph's start, as the running processes agreed it
    for (const auto& [name, s] : heard_)
      if (name != process_ && s.state() == "running" && s.start_ns() > 0 && (running_since == 0 || s.start_ns() < running_since))
        running_since = s.start_ns();
    if (ready_ns_ != 0 && running_since != 0) {
      start_ns_ = std::max(running_since, WallNowNs());  // an agreed start still ahead is kept
      graph_start_ns_ = running_since;
      return start_ns_;
    }
    // The start every process computes alike: from the required processes' ready times only (a
    // process that is not required must not move it by being ready last).
    int64_t last_ready = Required(process_) ? ready_ns_ : 0;
    const std::string not_heard = NotReady(&last_ready);
    if (ready_ns_ != 0 && not_heard.empty()) {
      start_ns_ = graph_start_ns_ = last_ready + kStartMarginNs;
      return start_ns_;
    }
    if (std::chrono::steady_clock::now() >= deadline) return TimedOut(not_heard, missing_endpoints);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

StartBarrier::Peers StartBarrier::Hear(double fresh_s) {
  TakeAnnouncements();
  const auto now = std::chrono::steady_clock::now();
  Peers out;
  bool owed = false;
  std::chrono::steady_clock::time_point last{};
  for (const auto& [name, s] : heard_) {
    if (name == process_) continue;
    const auto at = heard_at_[name];
    if (s.state() == "running" && std::chrono::duration<double>(now - at).count() <= fresh_s) out.running.insert(name);
    if (!Required(name)) continue;
    owed |= s.state() == "running";
    last = std::max(last, at);
  }
  if (owed) out.silence_s = std::chrono::duration<double>(now - last).count();
  return out;
}

}  // namespace dyad
