// Validation's last step: every component's own Configure() against a dry context, so `dyad
// validate` (and `dyad run` before it starts anything) reports what a component would reject:
// semantic checks of params, files that must exist, a model that does not fit its data set.
//
// Why Configure and not a separate check hook: the rules then live once, where the component
// reads its params, and built-in and third-party components get validated the same way with no
// extra code. It relies on the contract of component.hpp: Configure reads params, looks up
// ports and may load files, but acts on nothing (files are written, hardware is moved, servers
// are started in Activate).
//
// The dry context is the real one without DDS: the process's graph topics, ports bound as the
// graph binds them (to endpoints that read nothing and drop what is written), SubscribeSerialized
// and AdvertiseSerialized checked as in a run but connected to nothing.
//
// A failure is placed where it belongs: its message names a param (`params.model: ...`,
// `events[1].primitve: ...`, `components.x.params.gain = ...`), and the diagnostic points at that
// param's node in the graph file, or at the element inside it, or at the `--set` that set it.
#include <cstdio>
#include <memory>
#include <regex>
#include <span>
#include <sstream>

#include <dyad/on_demand_subscription.hpp>
#include <dyad/validate.hpp>

#include "graph/graph_topics.hpp"

namespace dyad {
namespace {

class NullReader final : public detail::ReaderEndpoint {
 public:
  bool TakeNext(void*) override { return false; }
};
class NullWriter final : public detail::WriterEndpoint {
 public:
  Status Write(const void*) override { return Status::OK(); }
};
class NullSerializedWriter final : public SerializedWriter {
 public:
  NullSerializedWriter(std::string topic, const TypeInfo& type) : topic_(std::move(topic)), type_(type) {}
  const std::string& topic() const override { return topic_; }
  const TypeInfo& type() const override { return type_; }
  Status Write(std::span<const uint8_t>, int64_t) override { return Status::OK(); }
  uint64_t written() const override { return 0; }

 private:
  std::string topic_;
  const TypeInfo& type_;
};
class NullOnDemandSubscription final : public OnDemandSubscription {
 public:
  explicit NullOnDemandSubscription(std::string topic) : topic_(std::move(topic)) {}
  const std::string& topic() const override { return topic_; }
  Status Start() override { started_ = true; return Status::OK(); }
  void Stop() override { started_ = false; }
  bool started() const override { return started_; }

 private:
  std::string topic_;
  bool started_ = false;
};
class ZeroClock final : public Clock {
 public:
  int64_t now_ns() const override { return 0; }
};
class QuietLogger final : public Logger {
 public:
  void Write(Level, std::string_view) override {}
};

class DryContext final : public Context, public detail::ContextExtensions {
 public:
  // `access`, when given, collects the topics the component reads and writes.
  DryContext(const Graph& graph, const ResolvedComponent& rc, const Catalog& catalog, const std::vector<TopicInfo>& topics,
             TopicAccess* access)
      : graph_(graph), rc_(rc), catalog_(catalog), topics_(topics), access_(access) {
    const ComponentSpec& spec = rc.entry->spec;
    for (const auto& ps : spec.inputs()) {
      auto port = ps.make_input();
      for (const auto& b : rc.config->inputs)
        if (b.port == ps.name) {
          port->Bind(ps.name, b.topic, &null_reader_);
          if (access_) access_->reads.insert(b.topic);
        }
      inputs_.push_back(std::move(port));
    }
    for (const auto& ps : spec.outputs()) {
      auto port = ps.make_output();
      for (const auto& b : rc.config->outputs)
        if (b.port == ps.name) {
          port->Bind(ps.name, b.topic, rc.config->name, &null_writer_, &clock_);
          if (access_) access_->writes.insert(b.topic);
        }
      outputs_.push_back(std::move(port));
    }
  }
  const std::string& name() const override { return rc_.config->name; }
  const Params& params() const override { return rc_.params; }
  const Clock& clock() const override { return clock_; }
  Logger& log() override { return logger_; }
  uint64_t seed() const override { return ComponentSeed(graph_.seed, name()); }
  int64_t period_ns() const override { return rc_.period_ns; }
  void RequestStop(std::string) override {}
  const std::string& graph_name() const override { return graph_.name; }
  const std::string& graph_yaml() const override { return graph_.yaml_text; }
  const std::string& graph_folder() const override { return graph_.folder; }
  bool stepped() const override { return graph_.clock == ClockMode::kStepped; }
  const std::vector<TopicInfo>& graph_topics() const override { return topics_; }
  const TypeInfo* FindMessageType(std::string_view name) const override {
    for (const auto& t : topics_)
      if (t.type->name == name || t.type->short_name() == name) return t.type;
    return catalog_.FindMessageType(std::string(name));
  }
  Status SubscribeSerialized(const std::string& topic, SerializedCallback) override {
    for (const auto& t : topics_)
      if (t.name == topic) {
        if (access_) access_->reads.insert(topic);
        return Status::OK();
      }
    return Status::NotFound("topic '" + topic + "' is not a topic of graph '" + graph_.name + "'");
  }
  StatusOr<OnDemandSubscription*> SubscribeSerializedOnDemand(const std::string& topic, SerializedCallback callback) override {
    if (Status s = SubscribeSerialized(topic, std::move(callback)); !s.ok()) return s;
    on_demand_.push_back(std::make_unique<NullOnDemandSubscription>(topic));
    return on_demand_.back().get();
  }
  StatusOr<SerializedWriter*> AdvertiseSerialized(const std::string& topic, const TypeInfo& type) override {
    for (const auto& t : topics_)
      if (t.name == topic && t.type->name != type.name)
        return Status::InvalidArgument("topic '" + topic + "' carries " + t.type->name + " in graph '" + graph_.name +
                                       "', not " + type.name);
    if (access_) access_->writes.insert(topic);
    writers_.push_back(std::make_unique<NullSerializedWriter>(topic, type));
    return writers_.back().get();
  }

 protected:
  InputBase* FindInput(std::string_view port, const TypeInfo& type) override {
    const auto& ins = rc_.entry->spec.inputs();
    for (size_t i = 0; i < ins.size(); ++i)
      if (ins[i].name == port && ins[i].type->name == type.name) return inputs_[i].get();
    std::fprintf(stderr, "dyad: component '%s' asked for an input it did not declare\n", name().c_str());
    std::abort();
  }
  OutputBase* FindOutput(std::string_view port, const TypeInfo& type) override {
    const auto& outs = rc_.entry->spec.outputs();
    for (size_t i = 0; i < outs.size(); ++i)
      if (outs[i].name == port && outs[i].type->name == type.name) return outputs_[i].get();
    std::fprintf(stderr, "dyad: component '%s' asked for an output it did not declare\n", name().c_str());
    std::abort();
  }

 private:
  const Graph& graph_;
  const ResolvedComponent& rc_;
  const Catalog& catalog_;
  const std::vector<TopicInfo>& topics_;
  TopicAccess* access_;
  ZeroClock clock_;
  QuietLogger logger_;
  NullReader null_reader_;
  NullWriter null_writer_;
  std::vector<std::unique_ptr<InputBase>> inputs_;
  std::vector<std::unique_ptr<OutputBase>> outputs_;
  std::vector<std::unique_ptr<NullSerializedWriter>> writers_;
  std::vector<std::unique_ptr<NullOnDemandSubscription>> on_demand_;
};

// Where a Configure message points: "components.<c>.params.<path>: msg", "params.<path>: msg" or
// "<path>: msg", <path> = param[.key|[i]]*, param one of the component's. Returns the mark of the
// deepest node of the path that exists (or of the --set that set the param), the key path and
// the message without it; false when the message names no param.
bool PlaceMessage(const Graph& graph, const ComponentConfig& c, const ComponentSpec& spec, const std::string& message,
                  Diagnostic* d) {
  std::string rest = message;
  const std::string own = "components." + c.name + ".";
  if (rest.rfind(own, 0) == 0) rest = rest.substr(own.size());
  if (rest.rfind("params.", 0) == 0) rest = rest.substr(7);
  static const std::regex kPath(R"(^([A-Za-z_][A-Za-z0-9_]*)((?:\.[A-Za-z_][A-Za-z0-9_]*|\[[0-9]+\])*))");
  std::smatch m;
  if (!std::regex_search(rest, m, kPath) || spec.FindParam(m[1].str()) == nullptr) return false;
  const std::string param = m[1].str(), tail = m[2].str();
  d->key = "components." + c.name + ".params." + param + tail;
  std::string msg = rest.substr(m[0].length());
  if (msg.rfind(": ", 0) == 0) msg = msg.substr(2);
  else if (msg.rfind(" = ", 0) == 0) msg = msg.substr(1);  // "= 300: must be ...": Diagnostic shows "key = 300: ..."
  else if (!msg.empty() && msg[0] == ' ') msg = msg.substr(1);
  d->message = msg;
  const std::string param_key = "components." + c.name + ".params." + param;
  if (const std::string& from = graph.OriginOf(param_key); from.rfind("--set ", 0) == 0) {
    d->mark = graph.MarkOf(param_key, YAML::Node());
    return true;
  }
  YAML::Node node = c.params && c.params.IsMap() ? c.params[param] : YAML::Node();
  if (!node) {
    d->mark = c.params_mark.line ? c.params_mark : c.mark;
    return true;
  }
  d->mark = graph.MarkOf(param_key, node);
  // Walk into the value: a kYaml param (e.g. events) as written in the file.
  static const std::regex kStep(R"(\.([A-Za-z_][A-Za-z0-9_]*)|\[([0-9]+)\])");
  for (auto it = std::sregex_iterator(tail.begin(), tail.end(), kStep); it != std::sregex_iterator(); ++it) {
    YAML::Node next;
    if ((*it)[1].matched && node.IsMap()) {
      for (const auto& kv : node)
        if (kv.first.Scalar() == (*it)[1].str()) next = kv.first;  // the key's own position
      if (next) {
        d->mark = graph.MarkOf(param_key, next);
        node = node[(*it)[1].str()];
        continue;
      }
    } else if ((*it)[2].matched && node.IsSequence()) {
      const size_t i = std::stoul((*it)[2].str());
      if (i < node.size()) next = node[i];
    }
    if (!next) break;
    node = next;
    d->mark = graph.MarkOf(param_key, node);
  }
  return true;
}

// A plugin's Configure that throws (a file it reads with yaml-cpp, a bad conversion) is a problem
// of its component, said at its line, not an abort of `dyad validate`.
Status ConfigureCatching(Component& component, DryContext& ctx) {
  try {
    return component.Configure(ctx);
  } catch (const std::exception& e) {
    return Status::InvalidArgument(std::string("configuring it threw: ") + e.what());
  }
}

void Configure(const Graph& graph, const ResolvedGraph& resolved, const Catalog& catalog,
               std::vector<Diagnostic>* diagnostics, const std::set<std::string>& only_processes,
               std::map<std::string, TopicAccess>* access) {
  for (const auto& rc : resolved.components) {
    if (rc.entry == nullptr) continue;
    if (!only_processes.empty() && !only_processes.count(graph.ProcessOf(*rc.config))) continue;
    const std::string key = "components." + rc.config->name;
    bool has_problem = false;  // a component with problems of its own has no complete params
    for (const auto& d : *diagnostics)
      if (d.key == key || d.key.rfind(key + ".", 0) == 0) has_problem = true;
    if (has_problem) continue;
    const std::string process = graph.ProcessOf(*rc.config);
    const auto topics = GraphTopics(graph, resolved, process);
    DryContext ctx(graph, rc, catalog, topics, access ? &(*access)[process] : nullptr);
    std::unique_ptr<Component> component = rc.entry->type.create();
    const Status s = ConfigureCatching(*component, ctx);
    if (s.ok()) {
      component->Shutdown();
      continue;
    }
    Diagnostic d;
    if (!PlaceMessage(graph, *rc.config, rc.entry->spec, s.message(), &d)) {
      d.mark = rc.config->mark;
      d.key = key;
      d.message = s.message();
    }
    diagnostics->push_back(std::move(d));
  }
}

}  // namespace

void DryConfigure(const Graph& graph, const ResolvedGraph& resolved, const Catalog& catalog,
                  std::vector<Diagnostic>* diagnostics, const std::set<std::string>& only_processes) {
  Configure(graph, resolved, catalog, diagnostics, only_processes, nullptr);
}

std::map<std::string, TopicAccess> TopicAccessByProcess(const Graph& graph, const ResolvedGraph& resolved,
                                                         const Catalog& catalog, std::vector<Diagnostic>* diagnostics) {
  std::map<std::string, TopicAccess> access;
  for (const std::string& p : graph.ProcessNames()) access[p];
  Configure(graph, resolved, catalog, diagnostics, {}, &access);
  return access;
}

}  // namespace dyad
