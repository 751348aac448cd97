#include "launcher_link.hpp"

#include <unistd.h>

#include <dyad/message_traits.hpp>
#include <dyad/msg/types.hpp>

#include "dds_participant.hpp"
#include "start_barrier.hpp"
#include "wall_clock.hpp"

namespace dyad {

LauncherLink::LauncherLink(const Graph& graph, std::string host) : graph_(graph), host_(std::move(host)) {}
LauncherLink::~LauncherLink() = default;

StatusOr<std::unique_ptr<LauncherLink>> LauncherLink::Open(const Graph& graph, const std::string& host) {
  std::unique_ptr<LauncherLink> link(new LauncherLink(graph, host));
  auto p = DdsParticipant::Create(graph.domain_id, "dyad/launcher/" + host, nullptr, DdsParticipant::Scope::kWatcher,
                                  graph.network);
  if (!p.ok()) return p.status().WithContext("the launcher's link to the other hosts");
  link->participant_ = std::move(p.value());
  // The QoS of the processes' own announcements (StartBarrier::Open), so that both match.
  auto w = link->participant_->CreateWriter(kProcessesTopic, TypeInfoOf<msg::ProcessState>(),
                                            TopicQos{Reliability::kReliable, 1, 0, false, true});
  if (!w.ok()) return w.status().WithContext(kProcessesTopic);
  link->writer_ = w.value();
  auto r = link->participant_->CreateReader(kProcessesTopic, TypeInfoOf<msg::ProcessState>(),
                                            TopicQos{Reliability::kReliable, 8, 0, false, true}, nullptr);
  if (!r.ok()) return r.status().WithContext(kProcessesTopic);
  link->reader_ = r.value();
  return link;
}

void LauncherLink::AnnounceFailure(const std::string& process, int restarts) {
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
  if (!writer_->Write(&m).ok()) return;
  static_cast<DdsWriter*>(writer_)->AwaitAcknowledged(2.0);
}

std::optional<std::string> LauncherLink::TakeRemoteFailure() {
  msg::ProcessState m;
  while (reader_->TakeNext(&m)) {
    if (reported_ || m.graph_name() != graph_.name || m.state() != "failed" || m.host() == host_) continue;
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
