#include "exec/live_params.hpp"

#include <yaml-cpp/yaml.h>

#include "dyad/join_list.hpp"
#include "dyad/validate.hpp"
#include "graph/runtime_topics.hpp"

namespace dyad {

Status LiveParams::Open(Transport* transport, const std::string& graph_name, const std::string& process, const Clock* clock,
                        std::vector<Target*> targets) {
  graph_name_ = graph_name;
  targets_ = std::move(targets);
  queues_.resize(targets_.size());
  auto r = CreateRuntimeReader(transport, runtime_topics::kParamRequests,
                               [this] { arrived_.store(true, std::memory_order_release); });
  if (!r.ok()) return r.status();
  reader_ = r.value();
  auto w = CreateRuntimeWriter(transport, runtime_topics::kParams);
  if (!w.ok()) return w.status();
  answers_ = std::make_unique<Output<msg::ParamChange>>();
  answers_->Bind("params", runtime_topics::kParams.name, "dyad/" + process, w.value(), clock);
  return Status::OK();
}

// Moves every waiting request for one of this process's components into its queue.
void LiveParams::Take() {
  arrived_.store(false, std::memory_order_release);  // before taking: a sample arriving now raises it again
  msg::ParamChange request;
  while (reader_->TakeNext(&request)) {
    if (request.graph_name() != graph_name_ || (request.op() != "set" && request.op() != "get")) continue;
    for (size_t i = 0; i < targets_.size(); ++i)
      if (targets_[i]->component == request.component_name()) {
        queues_[i].push_back(request);
        queued_.fetch_add(1, std::memory_order_release);
      }
  }
}

void LiveParams::Apply(size_t index) {
  std::vector<msg::ParamChange> mine;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    Take();
    mine.swap(queues_[index]);
    queued_.fetch_sub(static_cast<int>(mine.size()), std::memory_order_release);
  }
  for (const auto& request : mine) Publish(Answer(*targets_[index], request));
}

msg::ParamChange LiveParams::Answer(Target& target, const msg::ParamChange& request) {
  msg::ParamChange a = request;
  a.step(*target.steps);
  a.old_value("");
  a.reason("");
  auto refuse = [&](const std::string& why) {
    a.op("refused");
    a.reason(why);
    target.log->Warn("param " + request.param_name() + " = " + request.value() + " (" + request.who() + "): refused: " + why);
    return a;
  };
  const ParamSpec* spec = target.spec->FindParam(request.param_name());
  std::vector<std::string> live;
  for (const auto& p : target.spec->params())
    if (p.live) live.push_back(p.name);
  if (spec == nullptr) return refuse("no parameter '" + request.param_name() + "' (live: " + (live.empty() ? "none" : JoinList(live)) + ")");
  if (!spec->live)
    return refuse("'" + request.param_name() + "' is not live: read once, at configure (live: " + (live.empty() ? "none" : JoinList(live)) + ")");
  const std::string old = ToYamlText(target.params->values().at(request.param_name()));
  if (request.op() == "get") {
    a.op("value");
    a.value(old);
    return a;
  }
  YAML::Node node;
  try {
    node = YAML::Load(request.value());
  } catch (const YAML::Exception& e) {
    return refuse("not YAML: " + std::string(e.what()));
  }
  StatusOr<ParamValue> value = ParamFromYaml(*spec, node);
  if (!value.ok()) return refuse(value.status().message());
  if (auto check = target.checks.find(request.param_name()); check != target.checks.end())
    if (Status s = check->second(*value); !s.ok()) return refuse(s.message());
  a.op("applied");
  a.old_value(old);
  a.value(ToYamlText(*value));
  target.params->Set(request.param_name(), std::move(value).value());
  target.log->Info("param " + request.param_name() + ": " + old + " -> " + a.value() + " (" + request.who() + ")");
  return a;
}

void LiveParams::Publish(msg::ParamChange answer) {
  std::lock_guard<std::mutex> lock(publish_mutex_);
  answers_->Publish(answer).IgnoreError();  // the log has said it too
}

}  // namespace dyad
