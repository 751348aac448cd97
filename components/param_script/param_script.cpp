#include "param_script.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include <yaml-cpp/yaml.h>

namespace dyad::param_script {
namespace {

// The graph's component names (from the graph as run).
std::set<std::string> ComponentNames(const std::string& graph_yaml) {
  std::set<std::string> names;
  try {
    const YAML::Node g = YAML::Load(graph_yaml);
    if (g["components"] && g["components"].IsMap())
      for (const auto& kv : g["components"]) names.insert(kv.first.Scalar());
  } catch (const YAML::Exception&) {
  }
  return names;
}

std::string FlowText(const YAML::Node& node) {
  YAML::Emitter e;
  e << YAML::Flow << node;
  return e.c_str();
}

// The schedule from the `changes` param; errors name the element ("params.changes[1].at_s: ...").
StatusOr<std::vector<ParamScript::Change>> ParseChanges(const std::string& text, const std::set<std::string>& components) {
  YAML::Node list;
  try {
    list = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    return Status::InvalidArgument(std::string("params.changes: not YAML: ") + e.what());
  }
  if (!list.IsSequence()) return Status::InvalidArgument("params.changes: must be a list of {at_s: S, set: {COMPONENT.PARAM: VALUE}}");
  std::vector<ParamScript::Change> changes;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string key = "params.changes[" + std::to_string(i) + "]";
    const YAML::Node item = list[i];
    if (!item.IsMap()) return Status::InvalidArgument(key + ": must be a mapping {at_s: S, set: {COMPONENT.PARAM: VALUE}}");
    for (const auto& kv : item)
      if (kv.first.Scalar() != "at_s" && kv.first.Scalar() != "set")
        return Status::InvalidArgument(key + "." + kv.first.Scalar() + ": unknown key (known: at_s, set)");
    double at = -1;
    try {
      at = item["at_s"].as<double>();
    } catch (const YAML::Exception&) {
    }
    if (!std::isfinite(at) || at < 0 || at > 1e9) return Status::InvalidArgument(key + ".at_s: must be a number of seconds >= 0");
    const YAML::Node set = item["set"];
    if (!set || !set.IsMap() || set.size() == 0)
      return Status::InvalidArgument(key + ".set: must be a mapping {COMPONENT.PARAM: VALUE, ...}");
    for (const auto& kv : set) {
      const std::string name = kv.first.Scalar();
      const size_t dot = name.find('.');
      if (dot == std::string::npos || dot == 0 || dot + 1 == name.size())
        return Status::InvalidArgument(key + ".set." + name + ": must be COMPONENT.PARAM");
      const std::string component = name.substr(0, dot);
      if (!components.count(component)) {
        std::string known;
        for (const auto& c : components) known += (known.empty() ? "" : ", ") + c;
        return Status::InvalidArgument(key + ".set." + name + ": no component '" + component + "' in the graph (components: " + known + ")");
      }
      changes.push_back({static_cast<int64_t>(std::llround(at * 1e9)), component, name.substr(dot + 1), FlowText(kv.second)});
    }
  }
  std::stable_sort(changes.begin(), changes.end(), [](const auto& a, const auto& b) { return a.at_ns < b.at_ns; });
  return changes;
}

}  // namespace

void ParamScript::Describe(ComponentSpec& spec) {
  spec.Summary("Changes live parameters of the graph's components on a schedule (requests on dyad/param_requests).");
  spec.RequiredParam("changes", ParamType::kYaml).Doc("[{at_s: S, set: {COMPONENT.PARAM: VALUE, ...}}, ...]: seconds after the first step");
  spec.Output<msg::ParamChange>("requests").Doc("bind to dyad/param_requests");
}

Status ParamScript::Configure(Context& ctx) {
  ctx_ = &ctx;
  auto changes = ParseChanges(ctx.params().String("changes"), ComponentNames(ctx.graph_yaml()));
  if (!changes.ok()) return changes.status();
  changes_ = std::move(changes).value();
  out_ = &ctx.output<msg::ParamChange>("requests");
  if (!out_->bound()) return Status::InvalidArgument("outputs.requests: not bound (bind it to dyad/param_requests)");
  return Status::OK();
}

Status ParamScript::Step(const StepInfo& info) {
  if (first_ns_ < 0) first_ns_ = info.now_ns;
  for (; next_ < changes_.size() && changes_[next_].at_ns <= info.now_ns - first_ns_; ++next_) {
    const Change& c = changes_[next_];
    msg::ParamChange request;
    request.graph_name(ctx_->graph_name());
    request.component_name(c.component);
    request.param_name(c.param);
    request.op("set");
    request.value(c.value);
    request.who("param_script " + ctx_->name());
    request.request_id(ctx_->name() + "/" + std::to_string(next_));
    if (Status s = out_->Publish(request); !s.ok()) return s;
    ctx_->log().Info("asked " + c.component + "." + c.param + " = " + c.value);
  }
  return Status::OK();
}

}  // namespace dyad::param_script

DYAD_PLUGIN(registry) { registry.Add<dyad::param_script::ParamScript>("param_script"); }
