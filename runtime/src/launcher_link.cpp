#include "launcher_link.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <set>
#include <thread>

#include <dyad/message_traits.hpp>
#include <dyad/msg/types.hpp>

#include "dds_participant.hpp"
#include "start_barrier.hpp"
#include "wall_clock.hpp"

namespace dyad {

LauncherLink::LauncherLink(const Graph& graph, std::string host) : graph_(graph), host_(std::move(host)) {}
LauncherLink::~LauncherLink() = default;

StatusOr<std::unique_ptr<LauncherLink>> LauncherLink::Open(const Graph& graph, const std::string& host) {
  if (graph.network.transport == NetTransport::kTcp)
    return Status::Unimplemented("with network.transport: tcp the launchers cannot reach each other (only the processes listen)");
  std::unique_ptr<LauncherLink> link(new LauncherLink(graph, host));
  link->started_ns_ = WallNowNs();
  std::set<std::string> others;
  for (const auto& pc : graph.processes)
    if (!pc.host.empty() && pc.host != host) others.insert(pc.host);
  link->other_hosts_ = static_cast<int>(others.size());
  auto p = DdsParticipant::Create(graph.domain_id, "dyad/launcher/" + host, nullptr, DdsParticipant::Scope::kWatcher,
                                  graph.network);
  if (!p.ok()) return p.status();
  link->participant_ = std::move(p.value());
  // The QoS of the processes' own announcements (StartBarrier::Open), so that they match too.
  const TopicQos writer_qos{Reliability::kReliable, 1, 0, false, true};
  auto lw = link->participant_->CreateWriter(kLaunchersTopic, TypeInfoOf<msg::ProcessState>(), writer_qos);
  if (!lw.ok()) return lw.status().WithContext(kLaunchersTopic);
  link->launchers_writer_ = lw.value();
  auto pw = link->participant_->CreateWriter(kProcessesTopic, TypeInfoOf<msg::ProcessState>(), writer_qos);
  if (!pw.ok()) return pw.status().WithContext(kProcessesTopic);
  link->processes_writer_ = pw.value();
  auto r = link->participant_->CreateReader(kLaunchersTopic, TypeInfoOf<msg::ProcessState>(),
                                            TopicQos{Reliability::kReliable, 64, 0, false, true}, nullptr);
  if (!r.ok()) return r.status().WithContext(kLaunchersTopic);
  link->reader_ = r.value();
  return link;
}

bool LauncherLink::AnnounceFailure(const std::string& process, int restarts) {
  msg::ProcessState m;
  m.header().source("dyad/launcher/" + host_);
  m.header().sequence_number(1);
  m.header().stamp_ns(WallNowNs());
  m.graph_name(graph_.name);
  m.process_name(process);
  m.host(host_);
  m.pid(static_cast<int32_t>(getpid()));  // the launcher's: the process is gone
  m.state("failed");
  m.restarts(static_cast<uint32_t>(restarts));
  (void)processes_writer_->Write(&m);  // for `dyad status` and the recorder: no waiting
  if (!launchers_writer_->Write(&m).ok()) return false;
  // Every other host's launcher (this one's own reader matches too), then their acknowledgments.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (launchers_writer_->matched() < other_hosts_ + 1 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const double left = std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
  const bool acked = static_cast<DdsWriter*>(launchers_writer_)->AwaitAcknowledged(std::max(0.0, left));
  return acked && launchers_writer_->matched() >= other_hosts_ + 1;
}

std::optional<std::string> LauncherLink::TakeRemoteFailure() {
  msg::ProcessState m;
  while (reader_->TakeNext(&m)) {
    if (reported_ || m.graph_name() != graph_.name || m.state() != "failed" || m.host() == host_) continue;
    if (m.header().stamp_ns() < started_ns_) continue;  // an earlier run's
    bool required = true;
    for (const auto& pc : graph_.processes)
      if (pc.name == m.process_name()) required = pc.required;
    if (!required) continue;
    reported_ = true;
    std::string text = "process '" + m.process_name() + "' on host '" + m.host() + "' failed for good";
    if (m.restarts() > 0) text += " (after " + std::to_string(m.restarts()) + (m.restarts() == 1 ? " restart)" : " restarts)");
    return text;
  }
  return std::nullopt;
}

}  // namespace dyad
