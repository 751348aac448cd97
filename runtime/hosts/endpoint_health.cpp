#include "hosts/endpoint_health.hpp"

#include "exec/logger.hpp"
#include "graph/runtime_topics.hpp"

namespace dyad {

EndpointHealth::EndpointHealth(const Graph& graph, std::string process, double lost_s, Report report)
    : process_(std::move(process)),
      lost_s_(lost_s),
      report_(std::move(report)),
      tcp_(graph.network.transport == NetTransport::kTcp) {
  for (const auto& c : graph.components) {
    const std::string p = graph.ProcessOf(c);
    for (const auto& b : c.outputs) ++writers_in_[b.topic][p];
    for (const auto& b : c.inputs) ++readers_in_[b.topic][p];
  }
  for (const auto& p : graph.ProcessNames()) {
    ++writers_in_[runtime_topics::kProcesses.name][p];
    ++readers_in_[runtime_topics::kProcesses.name][p];
  }
}

void EndpointHealth::Tell(const std::string& topic, const char* endpoint, const char* action, int matched, int expected,
                          double starved_s, int renewals) {
  if (!report_) return;
  msg::HealthEvent e;
  e.topic(topic);
  e.endpoint(endpoint);
  e.action(action);
  e.matched(matched);
  e.expected(expected);
  e.starved_s(starved_s);
  e.renewals(static_cast<uint32_t>(renewals));
  report_(std::move(e));
}

int EndpointHealth::Expected(const std::string& topic, bool writer, const std::set<std::string>& running) const {
  const auto& table = writer ? readers_in_ : writers_in_;
  const auto it = table.find(topic);
  if (it == table.end()) return 0;
  int n = 0;
  for (const auto& [process, count] : it->second)
    if (process == process_ || running.count(process)) n += count;
  return n;
}

Status EndpointHealth::Check(Transport* transport, const std::set<std::string>& running, double silence_s,
                             std::chrono::steady_clock::time_point now) {
  transport->Reap();
  if (tcp_ && silence_s >= lost_s_ && !silence_said_) {
    silence_said_ = true;
    StderrLogger("health").Warn("no other process heard for " + std::to_string(static_cast<int>(silence_s)) +
                                " s although one should be running; with transport tcp the participant is not renewed "
                                "(its listener's port is taken): TCP reconnects once the network is back");
  }
  if (silence_s < lost_s_) silence_said_ = false;
  if (!tcp_ && silence_s >= lost_s_ &&
      (participant_renewals_ == 0 || std::chrono::duration<double>(now - participant_renewed_).count() >= lost_s_)) {
    RenewParticipant(transport, silence_s, now);
    return Status::OK();
  }
  return CheckEndpoints(transport, running, now);
}

void EndpointHealth::RenewParticipant(Transport* transport, double silence_s, std::chrono::steady_clock::time_point now) {
  const std::string why = "no other process heard for " + std::to_string(static_cast<int>(silence_s)) +
                          " s although one should be running: this process may be lost to discovery; ";
  if (!transport->RenewParticipant()) {
    if (!postponed_) {
      StderrLogger("health").Warn(why + "its participant is renewed once the network is up");
      Tell("", "participant", "postponed", 0, 0, silence_s, participant_renewals_);
    }
    postponed_ = true;
    return;
  }
  postponed_ = false;
  ++participant_renewals_;
  participant_renewed_ = now;
  StderrLogger("health").Warn(why + "renewed its participant (renewal " + std::to_string(participant_renewals_) + ")");
  Tell("", "participant", "renewed", 0, 0, silence_s, participant_renewals_);
  starved_.clear();  // every endpoint is new
}

Status EndpointHealth::CheckEndpoints(Transport* transport, const std::set<std::string>& running,
                                      std::chrono::steady_clock::time_point now) {
  std::set<std::pair<std::string, bool>> starved_now;
  for (const auto& e : transport->Matches()) {
    if (e.writer && e.serialized) continue;  // a component's own writer (web, replay): not in the graph's bindings
    const bool runtime_topic = e.topic.rfind("dyad/", 0) == 0;
    if (runtime_topic && e.topic != runtime_topics::kProcesses.name) continue;
    const int expected = Expected(e.topic, e.writer, running);
    if (e.matched >= expected) continue;
    const auto key = std::make_pair(e.topic, e.writer);
    if (!starved_now.insert(key).second) continue;
    Starved& s = starved_.try_emplace(key, Starved{now, 0}).first->second;
    const double waited = std::chrono::duration<double>(now - s.since).count();
    if (waited < (e.writer ? kWriterS : kReaderS)) continue;
    const char* kind = e.writer ? "writer" : "reader";
    const std::string what = std::string("the ") + kind + " of '" + e.topic + "' matched " + std::to_string(e.matched) +
                             " of " + std::to_string(expected) + (e.writer ? " readers" : " writers") +
                             " of the running processes for " + std::to_string(static_cast<int>(waited + 0.5)) + " s";
    if (s.renewals >= kMaxRenewals) {
      Tell(e.topic, kind, "cannot heal", e.matched, expected, waited, s.renewals);
      return Status::DataLoss("health: " + what + ", after " + std::to_string(s.renewals) +
                              " renewals: cannot heal (discovery lost it for good)");
    }
    const int renewed = transport->Renew(e.topic, e.writer, expected);
    ++s.renewals;
    renewals_ += renewed;
    s.since = now;
    StderrLogger("health").Warn(what + ": discovery lost it; renewed " + std::to_string(renewed) + " endpoint(s) (renewal " +
                                std::to_string(s.renewals) + " of at most " + std::to_string(kMaxRenewals) + ")");
    Tell(e.topic, kind, "renewed", e.matched, expected, waited, s.renewals);
  }
  // Starved no more: said once for those that were renewed.
  for (auto it = starved_.begin(); it != starved_.end();) {
    if (starved_now.count(it->first)) {
      ++it;
      continue;
    }
    if (it->second.renewals > 0) {
      const char* kind = it->first.second ? "writer" : "reader";
      StderrLogger("health").Info(std::string("the ") + kind + " of '" + it->first.first + "' matches again");
      Tell(it->first.first, kind, "healed", 0, 0, std::chrono::duration<double>(now - it->second.since).count(),
           it->second.renewals);
    }
    it = starved_.erase(it);
  }
  return Status::OK();
}

}  // namespace dyad
