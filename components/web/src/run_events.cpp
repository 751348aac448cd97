#include "run_events.hpp"

#include <nlohmann/json.hpp>

namespace dyad::web {

void RunEvents::Push(double wall_s, std::string text) {
  items_.emplace_back(wall_s, std::move(text));
  while (items_.size() > kMaxItems) items_.pop_front();
}

void RunEvents::Add(const msg::ProcessState& s, double wall_s) {
  const std::string who = "process '" + s.process_name() + "'" + (s.host().empty() ? "" : " on host '" + s.host() + "'");
  std::lock_guard<std::mutex> lock(mutex_);
  if (s.state() == "failed") {
    if (failed_.insert(s.process_name()).second) Push(wall_s, who + " failed for good");
    return;
  }
  uint64_t& seen = restarts_[s.process_name()];
  if (s.restarts() <= seen) return;
  seen = s.restarts();
  Push(wall_s, who + " restarted (restart " + std::to_string(s.restarts()) +
                   "): its components started afresh, their state (a PV-RNN's adapted posterior, an observer's "
                   "window) was reset");
}

void RunEvents::Add(const msg::HealthEvent& e, double wall_s) {
  const std::string what = e.endpoint() == "participant" ? "its DDS participant" : "its " + e.endpoint() + " of '" + e.topic() + "'";
  const std::string who = "process '" + e.process_name() + "'";
  std::string text;
  if (e.action() == "renewed") {
    char detail[96];
    std::snprintf(detail, sizeof detail, " (it heard nothing for %.1f s; renewal %lu)", e.starved_s(),
                  static_cast<unsigned long>(e.renewals()));
    text = who + " renewed " + what + detail;
  } else if (e.action() == "healed") {
    text = who + ": " + what + " is matched again";
  } else if (e.action() == "cannot heal") {
    text = who + " cannot heal " + what + " after " + std::to_string(e.renewals()) + " renewals: it ends as failed";
  } else {
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  Push(wall_s, std::move(text));
}

std::string RunEvents::Json() const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (items_.empty()) return "";
  nlohmann::json items = nlohmann::json::array();
  for (const auto& [t, text] : items_) items.push_back({{"t", t}, {"text", text}});
  return nlohmann::json{{"op", "events"}, {"items", items}}.dump();
}

}  // namespace dyad::web
