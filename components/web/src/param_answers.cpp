#include "param_answers.hpp"

namespace dyad::web {

void ParamAnswers::Add(const msg::ParamChange& a, double wall_s) {
  if (a.graph_name() != graph_name_ || (a.op() != "applied" && a.op() != "refused" && a.op() != "value")) return;
  nlohmann::json item{{"t", wall_s},
                      {"component", a.component_name()},
                      {"param", a.param_name()},
                      {"op", a.op()},
                      {"value", a.value()},
                      {"old_value", a.old_value()},
                      {"reason", a.reason()},
                      {"who", a.who()},
                      {"step", a.step()},
                      {"request_id", a.request_id()}};
  std::lock_guard<std::mutex> lock(mutex_);
  items_.push_back(std::move(item));
  while (items_.size() > kMaxItems) items_.pop_front();
}

std::string ParamAnswers::Json() const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (items_.empty()) return "";
  nlohmann::json items = nlohmann::json::array();
  for (const auto& item : items_) items.push_back(item);
  const nlohmann::json j{{"op", "params"}, {"items", std::move(items)}};
  // Texts come from other processes: never let one that is not UTF-8 throw.
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace dyad::web
