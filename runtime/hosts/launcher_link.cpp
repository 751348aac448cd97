#include "hosts/launcher_link.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <set>
#include <thread>

#include <dyad/join_list.hpp>
#include <dyad/message_traits.hpp>
#include <dyad/msg/types.hpp>
#include <dyad/security.hpp>

#include "graph/run_partition.hpp"
#include "dds/dds_participant.hpp"
#include "hosts/start_barrier.hpp"
#include "exec/wall_clock.hpp"

namespace dyad {

LauncherLink::LauncherLink(const Graph& graph, std::string host) : graph_(graph), host_(std::move(host)) {}
LauncherLink::~LauncherLink() = default;

StatusOr<std::unique_ptr<LauncherLink>> LauncherLink::Open(const Graph& graph, const std::string& host) {
  std::unique_ptr<LauncherLink> link(new LauncherLink(graph, host));
  link->started_ns_ = WallNowNs();
  std::set<std::string> others;
  for (const auto& pc : graph.processes)
    if (!pc.host.empty() && pc.host != host) others.insert(pc.host);
  link->other_hosts_ = static_cast<int>(others.size());
  DdsParticipant::Options po;
  po.scope = DdsParticipant::Scope::kWatcher;
  po.network = graph.network;
  po.process = LauncherParticipantName(host);  // transport tcp: its listener (graph.hpp, tcp_listeners)
  po.partitions = {RunPartition(graph)};  // another run's launchers are not ours to hear
  if (graph.security.enabled()) {
    auto identity = HostIdentityFor(graph, host);
    if (!identity.ok()) return identity.status();
    if (Status s = CheckIdentityHeld(graph, identity.value()); !s.ok()) return s;
    po.security = IdentityOf(graph, identity.value());
  }
  auto p = DdsParticipant::Create(graph.domain_id, LauncherParticipantName(host), std::move(po));
  if (!p.ok()) return p.status();
  link->participant_ = std::move(p.value());
  auto lw = CreateRuntimeWriter(link->participant_.get(), runtime_topics::kLaunchers);
  if (!lw.ok()) return lw.status();
  link->launchers_writer_ = lw.value();
  auto pw = CreateRuntimeWriter(link->participant_.get(), runtime_topics::kProcesses);
  if (!pw.ok()) return pw.status();
  link->processes_writer_ = pw.value();
  auto r = CreateRuntimeReader(link->participant_.get(), runtime_topics::kLaunchers);
  if (!r.ok()) return r.status();
  link->reader_ = r.value();
  auto pr = CreateRuntimeReader(link->participant_.get(), runtime_topics::kProcesses);
  if (!pr.ok()) return pr.status();
  link->processes_reader_ = pr.value();
  return link;
}

bool LauncherLink::AnnounceFailure(const std::string& process, int restarts) {
  msg::ProcessState m;
  m.header().source(LauncherParticipantName(host_));
  m.header().sequence_number(1);
  m.header().stamp_ns(WallNowNs());
  m.graph_name(graph_.name);
  m.process_name(process);
  m.host(host_);
  m.pid(static_cast<int32_t>(getpid()));  // the launcher's: the process is gone
  m.state("failed");
  m.restarts(static_cast<uint32_t>(restarts));
  processes_writer_->Write(&m).IgnoreError();  // best effort, for `dyad status` and the recorder: no waiting
  if (!launchers_writer_->Write(&m).ok()) return false;
  // Every other host's launcher (this one's own reader matches too), then their acknowledgments.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (launchers_writer_->matched() < other_hosts_ + 1 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const double left = std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
  const bool acked = launchers_writer_->AwaitAcknowledged(std::max(0.0, left));
  return acked && launchers_writer_->matched() >= other_hosts_ + 1;
}

std::optional<std::string> LauncherLink::TakeRemoteFailure() {
  msg::ProcessState m;
  while (reader_->TakeNext(&m)) {
    if (reported_ || m.graph_name() != graph_.name || m.state() != "failed" || m.host() == host_) continue;
    if (m.header().stamp_ns() < started_ns_) continue;  // an earlier run's
    if (const ProcessConfig* pc = graph_.FindProcess(m.process_name()); pc != nullptr && !pc->required) continue;
    reported_ = true;
    std::string text = "process '" + m.process_name() + "' on host '" + m.host() + "' failed for good";
    if (m.restarts() > 0) text += " (after " + std::to_string(m.restarts()) + (m.restarts() == 1 ? " restart)" : " restarts)");
    return text;
  }
  return std::nullopt;
}

std::vector<std::string> LauncherLink::TakeRemoteRestarts() {
  std::vector<std::string> out;
  msg::ProcessState m;
  while (processes_reader_->TakeNext(&m)) {
    if (m.graph_name() != graph_.name || m.host() == host_ || m.state() == "failed") continue;
    uint32_t& seen = restarts_seen_[m.process_name()];
    if (m.restarts() <= seen) continue;
    seen = m.restarts();
    if (m.header().stamp_ns() < started_ns_) continue;  // said before this launcher started
    out.push_back(RestartNotice(graph_, m.process_name(), m.host(), m.restarts()));
  }
  return out;
}

std::string ResetClause(const Graph& graph, const std::string& process) {
  std::vector<std::string> components;
  for (const auto& c : graph.components)
    if (graph.ProcessOf(c) == process) components.push_back(c.name + ": " + c.type);
  return "its components' state is reset (" + JoinList(components) + ")";
}

std::string RestartNotice(const Graph& graph, const std::string& process, const std::string& host, uint32_t restarts) {
  return "process '" + process + "' on host '" + host + "' restarted (restart " + std::to_string(restarts) +
         "): " + ResetClause(graph, process);
}

}  // namespace dyad
