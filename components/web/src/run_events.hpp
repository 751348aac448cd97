/// RunEvents — what the experimenter must know happened to the run while it went on, for the
/// experimenter's page: a process its launcher restarted (its components started afresh: a
/// PV-RNN's adapted posterior, an observer's window are gone), a process that failed for good,
/// and what a process did about endpoints discovery lost (dyad/health: renewed, healed, cannot
/// heal). Fed from dyad/processes and dyad/health on DDS threads; Json() from any thread.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <set>
#include <string>

#include <dyad/msg/types.hpp>

namespace dyad::web {

class RunEvents {
 public:
  static constexpr size_t kMaxItems = 50;  // the newest; a page shows them newest first

  // A restart count higher than the last seen for that process (a process seen first with
  // restarts > 0 restarted before the page's component started: said once), or "failed".
  void Add(const msg::ProcessState& state, double wall_s);
  // renewed, healed, cannot heal (postponed is not news: the network is down, the log says so).
  void Add(const msg::HealthEvent& event, double wall_s);
  // {"op":"events","items":[{"t":wall seconds,"text":".."}, ...]}, oldest first; "" when none yet.
  std::string Json() const;

 private:
  void Push(double wall_s, std::string text);  // REQUIRES: mutex_ held
  mutable std::mutex mutex_;
  std::map<std::string, uint64_t> restarts_;  // process -> restarts seen
  std::set<std::string> failed_;
  std::deque<std::pair<double, std::string>> items_;
};

}  // namespace dyad::web
