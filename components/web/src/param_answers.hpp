/// ParamAnswers — the newest answers to live parameter requests (dyad/params: applied, refused,
/// a value asked for; docs/runtime.md, "Live parameters") for the experimenter's page, whoever
/// asked (the page, `dyad param`, a param_script). Fed from the dyad/params subscription on a DDS
/// thread; Json() from any thread.
#pragma once

#include <deque>
#include <mutex>
#include <string>

#include <nlohmann/json.hpp>

#include <dyad/msg/types.hpp>

namespace dyad::web {

class ParamAnswers {
 public:
  static constexpr size_t kMaxItems = 20;  // the newest

  explicit ParamAnswers(std::string graph_name) : graph_name_(std::move(graph_name)) {}
  // An answer of this graph's (op applied, refused or value), received at `wall_s`; anything
  // else (a request, another graph's answer) is not kept.
  void Add(const msg::ParamChange& answer, double wall_s);
  // {"op":"params","items":[{t, component, param, op, value, old_value, reason, who, step,
  // request_id}, ...]}, oldest first (newest last); "" when none yet.
  std::string Json() const;

 private:
  const std::string graph_name_;
  mutable std::mutex mutex_;
  std::deque<nlohmann::json> items_;
};

}  // namespace dyad::web
