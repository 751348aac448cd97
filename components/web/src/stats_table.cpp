#include "stats_table.hpp"

#include <nlohmann/json.hpp>

#include <dyad/decode_sample.hpp>

namespace dyad::web {

void StatsTable::Add(std::span<const uint8_t> cdr) {
  msg::ComponentStats s;
  if (!DecodeSample(cdr, &s).ok()) return;
  Key key{s.process_name(), s.component_name()};
  if (!graphs_own_.count(key)) return;
  std::lock_guard<std::mutex> lock(mutex_);
  rows_[std::move(key)] = std::move(s);
}

std::string StatsTable::Json() const {
  nlohmann::json list = nlohmann::json::array();
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [key, s] : rows_)
    list.push_back({{"process", s.process_name()}, {"component", s.component_name()}, {"steps", s.steps()},
                    {"mean_ms", s.step_mean_s() * 1e3}, {"p99_ms", s.step_p99_s() * 1e3}, {"max_ms", s.step_max_s() * 1e3},
                    {"misses", s.deadline_misses()}});
  return nlohmann::json{{"op", "stats"}, {"rows", list}}.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

size_t StatsTable::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return rows_.size();
}

}  // namespace dyad::web
