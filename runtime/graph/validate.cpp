// Graph validation: every check in one pass, every problem reported.
#include "dyad/validate.hpp"
#include "dyad/join_list.hpp"
#include "dyad/security.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <set>
#include <sstream>
#include <string_view>

namespace dyad {
namespace {

// "a, b, c" of the `name`s of params or ports, or "none".
template <class Spec>
std::string Names(const std::vector<Spec>& specs) {
  std::vector<std::string> names;
  for (const auto& s : specs) names.push_back(s.name);
  return names.empty() ? "none" : JoinList(names);
}

bool ScalarAs(const YAML::Node& node, double* out) {
  if (!node.IsScalar()) return false;
  try {
    *out = node.as<double>();
    return true;
  } catch (const YAML::Exception&) {
    return false;
  }
}

std::string RangeError(const ParamSpec& spec, double v) {
  std::ostringstream os;
  if (spec.min && v < *spec.min) os << "must be >= " << *spec.min << ", got " << v;
  else if (spec.max && v > *spec.max) os << "must be <= " << *spec.max << ", got " << v;
  return os.str();
}

}  // namespace

void ResolvePaths(const std::filesystem::path& base, ParamValue* value) {
  auto resolve = [&](std::string& p) {
    if (p.empty() || std::filesystem::path(p).is_absolute()) return;
    p = (base / p).lexically_normal().string();
  };
  if (auto* s = std::get_if<std::string>(value)) resolve(*s);
  if (auto* list = std::get_if<std::vector<std::string>>(value))
    for (std::string& p : *list) resolve(p);
}

StatusOr<ParamValue> ParamFromYaml(const ParamSpec& spec, const YAML::Node& node) {
  const std::string got = node.IsScalar() ? "'" + node.Scalar() + "'" : node.IsSequence() ? "a list" : node.IsMap() ? "a mapping" : "null";
  auto fail = [&](const std::string& what) -> StatusOr<ParamValue> {
    return Status::InvalidArgument("must be " + what + ", got " + got);
  };
  switch (spec.type) {
    case ParamType::kBool: {
      if (!node.IsScalar()) return fail("true or false");
      try {
        return ParamValue(node.as<bool>());
      } catch (const YAML::Exception&) {
        return fail("true or false");
      }
    }
    case ParamType::kInt: {
      if (!node.IsScalar()) return fail("an integer");
      try {
        const int64_t v = node.as<int64_t>();
        if (auto e = RangeError(spec, static_cast<double>(v)); !e.empty()) return Status::InvalidArgument(e);
        return ParamValue(v);
      } catch (const YAML::Exception&) {
        return fail("an integer");
      }
    }
    case ParamType::kDouble: {
      double v;
      if (!ScalarAs(node, &v) || !std::isfinite(v)) return fail("a finite number");
      if (auto e = RangeError(spec, v); !e.empty()) return Status::InvalidArgument(e);
      return ParamValue(v);
    }
    case ParamType::kString: {
      if (!node.IsScalar()) return fail("a string");
      if (!spec.choices.empty() && std::find(spec.choices.begin(), spec.choices.end(), node.Scalar()) == spec.choices.end())
        return fail("one of: " + JoinList(spec.choices));
      return ParamValue(node.Scalar());
    }
    case ParamType::kDoubleList: {
      if (!node.IsSequence()) return fail("a list of numbers");
      std::vector<double> v;
      for (const auto& e : node) {
        double x;
        if (!ScalarAs(e, &x) || !std::isfinite(x)) return fail("a list of numbers");
        if (auto err = RangeError(spec, x); !err.empty()) return Status::InvalidArgument("element " + err);
        v.push_back(x);
      }
      return ParamValue(v);
    }
    case ParamType::kStringList: {
      if (!node.IsSequence()) return fail("a list of strings");
      std::vector<std::string> v;
      for (const auto& e : node) {
        if (!e.IsScalar()) return fail("a list of strings");
        v.push_back(e.Scalar());
      }
      return ParamValue(v);
    }
    case ParamType::kYaml: {
      YAML::Emitter em;
      em << YAML::Flow << node;
      return ParamValue(std::string(em.c_str()));
    }
  }
  return fail("a valid value");
}

namespace {

// One validation of one graph: the steps of ValidateGraph, sharing what they collect.
class Validation {
 public:
  Validation(const Graph& graph, const Catalog& catalog, std::vector<Diagnostic>* diags)
      : graph_(graph), catalog_(catalog), diags_(diags) {}

  ResolvedGraph Run() {
    std::set<std::string> process_names;
    for (const auto& p : graph_.processes) process_names.insert(p.name);
    std::set<std::string> processes_used;
    for (const auto& c : graph_.components) {
      const std::string key = "components." + c.name;
      processes_used.insert(graph_.ProcessOf(c));
      if (!c.process.empty() && !graph_.processes.empty() && !process_names.count(c.process))
        error(c.process_mark, key + ".process", "no process '" + c.process + "' under processes:");
      ResolveComponent(c, key);
    }
    CheckDeclaredTypes();
    ResolveTopics();
    CheckClock(processes_used);
    CheckInterfaces();
    CheckSecurity();
    return std::move(out_);
  }

 private:
  // Topic -> (type, who) per writer and reader, for type checks and "nobody publishes".
  struct PortUse {
    const TypeInfo* type;
    std::string who;  // "components.x.outputs.y"
    SourceMark mark;
  };

  void error(const SourceMark& m, const std::string& key, const std::string& msg) { diags_->push_back(Diagnostic{m, key, msg}); }

  // A graph open to the network without `interfaces` talks on every interface of each host (the
  // lab's Wi-Fi too): said, not refused (a lab may mean it).
  void CheckInterfaces() {
    const NetworkConfig& n = graph_.network;
    if (n.scope != NetScope::kLan || !n.interfaces.empty()) return;
    warn(n.mark.line > 0 ? n.mark : SourceMark{graph_.file, 1, 1}, "network.interfaces",
         "not given: the graph's participants use every interface of each host (Wi-Fi included); name the experiment "
         "network's (e.g. interfaces: [eth0]), and see docs/security.md for DDS Security");
  }

  // The keystore holds what every participant of the graph needs (dyad/security.hpp).
  void CheckSecurity() {
    const SecurityConfig& s = graph_.security;
    if (!s.enabled()) return;
    if (graph_.network.discovery == Discovery::kServer)
      error(s.mark, "security.keystore",
            "Fast DDS 2.9 has no secure discovery server: use network.discovery: peers (or multicast) with security");
    for (const std::string& problem : CheckKeystore(graph_, static_cast<int64_t>(std::time(nullptr))))
      error(s.mark, "security.keystore", problem);
  }
  // Legal but likely a hole in the wiring: said, never refused.
  void warn(const SourceMark& m, const std::string& key, const std::string& msg) { out_.warnings.push_back(Diagnostic{m, key, msg}); }

  // Rate or trigger, type, params and ports of one component.
  void ResolveComponent(const ComponentConfig& c, const std::string& key) {
    ResolvedComponent rc;
    rc.config = &c;
    if (c.rate_hz > 0 && !c.trigger.empty())
      error(c.trigger_mark, key + ".trigger", "give either rate_hz or trigger, not both");
    if (c.rate_hz > 0) rc.period_ns = static_cast<int64_t>(std::llround(1e9 / c.rate_hz));

    const CatalogEntry* entry = c.type.empty() ? nullptr : catalog_.Find(c.type);
    if (entry == nullptr) {
      if (!c.type.empty()) {
        std::vector<std::string> known;
        for (const auto& [name, e] : catalog_.entries()) known.push_back(name);
        error(c.type_mark, key + ".type", "unknown component type '" + c.type + "' (known: " + JoinList(known) + ")");
      }
      return;
    }
    rc.entry = entry;
    const ComponentSpec& spec = entry->spec;

    if (!(c.rate_hz > 0) && c.trigger.empty() && !c.rate_mark.line)
      error(c.mark, key, "needs rate_hz (periodic) or trigger: <input> (steps when that input receives)");
    if (!c.trigger.empty() && spec.FindInput(c.trigger) == nullptr)
      error(c.trigger_mark, key + ".trigger", "'" + c.trigger + "' is not an input of type " + c.type);
    // An optional input left unbound never receives: triggered by it, the component would never step.
    if (!c.trigger.empty() && spec.FindInput(c.trigger) != nullptr) {
      bool bound = false;
      for (const auto& b : c.inputs) bound = bound || b.port == c.trigger;
      if (!bound)
        error(c.trigger_mark, key + ".trigger", "input '" + c.trigger + "' is not bound to a topic (inputs:), so it never "
                                                "receives and the component would never step");
    }

    rc.params = ResolveParams(c, spec, key);
    BindPorts(c, spec, key);
    out_.components.push_back(std::move(rc));
  }

  // Params: unknown, mistyped, out of range, missing; path params resolved.
  Params ResolveParams(const ComponentConfig& c, const ComponentSpec& spec, const std::string& key) {
    std::map<std::string, ParamValue> values;
    if (c.params && c.params.IsMap()) {
      for (const auto& kv : c.params) {
        const std::string pname = kv.first.Scalar();
        const std::string pkey = key + ".params." + pname;
        const SourceMark at = graph_.MarkOf(pkey, kv.second);
        const ParamSpec* ps = spec.FindParam(pname);
        if (ps == nullptr) {
          error(graph_.MarkOf(pkey, kv.first), pkey,
                "unknown parameter of " + c.type + " (known: " + Names(spec.params()) + ")");
          continue;
        }
        auto v = ParamFromYaml(*ps, kv.second);
        if (!v.ok()) {
          error(at, pkey, v.status().message());
          continue;
        }
        // Written in a file: relative to that file. Given with --set: relative to where the user is.
        if (ps->path) ResolvePaths(graph_.FolderOf(pkey), &v.value());
        values[pname] = std::move(v.value());
      }
    }
    for (const auto& ps : spec.params()) {
      if (values.count(ps.name)) continue;
      if (ps.default_value) values[ps.name] = *ps.default_value;
      else error(c.params_mark.line ? c.params_mark : c.mark, key + ".params." + ps.name,
                 std::string("missing required parameter (") + ToString(ps.type) + (ps.doc.empty() ? "" : ": " + ps.doc) + ")");
    }
    return Params(std::move(values));
  }

  // Ports: each bound port exists; required inputs are bound.
  void BindPorts(const ComponentConfig& c, const ComponentSpec& spec, const std::string& key) {
    std::set<std::string> bound_inputs;
    for (const auto& b : c.inputs) {
      const PortSpec* ps = spec.FindInput(b.port);
      if (ps == nullptr) {
        error(b.mark, key + ".inputs." + b.port, "no input '" + b.port + "' on type " + c.type + " (inputs: " + Names(spec.inputs()) + ")");
        continue;
      }
      bound_inputs.insert(b.port);
      readers_[b.topic].push_back({ps->type, key + ".inputs." + b.port, b.mark});
    }
    for (const auto& ps : spec.inputs())
      if (!ps.optional && !bound_inputs.count(ps.name))
        error(c.mark, key + ".inputs." + ps.name, "required input is not bound to a topic (" + ps.type->short_name() + ")");
    std::set<std::string> bound_outputs;
    for (const auto& b : c.outputs) {
      const PortSpec* ps = spec.FindOutput(b.port);
      if (ps == nullptr) {
        error(b.mark, key + ".outputs." + b.port, "no output '" + b.port + "' on type " + c.type + " (outputs: " + Names(spec.outputs()) + ")");
        continue;
      }
      bound_outputs.insert(b.port);
      writers_[b.topic].push_back({ps->type, key + ".outputs." + b.port, b.mark});
    }
    for (const auto& ps : spec.outputs())
      if (!bound_outputs.count(ps.name) && !ps.optional)
        warn(c.mark, key + ".outputs." + ps.name, "output is bound to no topic: what it writes goes nowhere (and is not recorded)");
  }

  // Declared topic types must exist; a ROS 2 topic names a ROS 2 type.
  void CheckDeclaredTypes() {
    for (const auto& t : graph_.topics) {
      const TypeInfo* type = t.type.empty() ? nullptr : catalog_.FindMessageType(t.type);
      if (!t.type.empty() && type == nullptr) {
        std::vector<std::string> known;
        for (const auto* ti : catalog_.MessageTypes()) known.push_back(ti->ros2() ? ti->ros2_name : ti->short_name());
        error(t.type_mark, "topics." + t.name + ".type", "unknown message type '" + t.type + "' (known: " + JoinList(known) + ")");
      }
      if (!t.ros2.empty()) CheckRos2Topic(t, type);
    }
  }

  void CheckRos2Topic(const TopicConfig& t, const TypeInfo* type) {
    const std::string key = "topics." + t.name;
    if (t.type.empty())
      error(t.ros2_mark, key + ".type", "a ROS 2 topic needs its type, e.g. type: geometry_msgs/msg/TwistStamped");
    else if (type != nullptr && !type->ros2()) {
      std::vector<std::string> known;
      for (const auto* ti : catalog_.MessageTypes())
        if (ti->ros2()) known.push_back(ti->ros2_name);
      error(t.type_mark, key + ".type", "'" + t.type + "' is a dyad type; ROS 2 topic '" + t.ros2 +
                                            "' needs a ROS 2 type (known: " + JoinList(known) + ")");
    }
    if (graph_.clock == ClockMode::kStepped)
      error(graph_.clock_mark.file.empty() ? t.ros2_mark : graph_.clock_mark, "clock",
            "topic '" + t.name + "' is ROS 2 topic " + t.ros2 + ", which programs outside the graph share: a stepped "
            "run sees no other process (use clock: wall)");
    for (const auto& other : graph_.topics)
      if (&other != &t && other.ros2 == t.ros2 && &other < &t)
        error(t.ros2_mark, key + ".ros2", "ROS 2 topic " + t.ros2 + " is also topics." + other.name + ".ros2");
  }

  // Topic types agree; every read topic has a writer.
  void ResolveTopics() {
    // A topic declared under `topics:` with a type is part of the graph even when no port writes it:
    // something outside the ports publishes it (a replay, another program).
    std::set<std::string> all_topics;
    for (const auto& [t, _] : writers_) all_topics.insert(t);
    for (const auto& [t, _] : readers_) all_topics.insert(t);
    for (const auto& t : graph_.topics)
      if (!t.type.empty() && catalog_.FindMessageType(t.type) != nullptr) all_topics.insert(t.name);
    for (const auto& name : all_topics) {
      if (!name.empty() && name[0] == '/') {
        const SourceMark mark = graph_.FindTopic(name) ? graph_.FindTopic(name)->mark : FirstUse(name);
        error(mark, "topics." + name, "a topic name starting with '/' is a ROS 2 name: declare a topic of the graph with "
                                      "ros2: " + name + " (and its type) instead");
        continue;
      }
      ResolvedTopic rt;
      rt.name = name;
      rt.config = graph_.FindTopic(name);
      const TypeInfo* declared = rt.config && !rt.config->type.empty() ? catalog_.FindMessageType(rt.config->type) : nullptr;
      std::vector<PortUse> uses = writers_[name];
      uses.insert(uses.end(), readers_[name].begin(), readers_[name].end());
      if (declared == nullptr && uses.empty()) continue;
      const TypeInfo* first = declared ? declared : uses.front().type;
      const std::string first_who = declared ? "topics." + name + ".type" : uses.front().who;
      for (const auto& u : uses) {
        if (u.type->name != first->name)
          error(u.mark, u.who, "topic '" + name + "' carries " + first->short_name() + " (" + first_who + ") but this port is " +
                                   u.type->short_name());
      }
      rt.type = first;
      if (writers_[name].empty() && declared == nullptr)
        for (const auto& u : readers_[name])
          error(u.mark, u.who, "nothing publishes topic '" + name + "' (no component output is bound to it)");
      if (writers_[name].empty() && declared != nullptr && rt.config->ros2.empty())  // ROS 2: the robot's side writes it
        warn(rt.config->mark, "topics." + name, "no component of the graph writes this topic: it must come from outside (a replay, another program)");
      out_.topics[name] = rt;
    }
  }

  SourceMark FirstUse(const std::string& topic) {
    if (!writers_[topic].empty()) return writers_[topic].front().mark;
    if (!readers_[topic].empty()) return readers_[topic].front().mark;
    return SourceMark{graph_.file, 1, 1};
  }

  // The stepped clock runs the graph in one process.
  void CheckClock(const std::set<std::string>& processes_used) {
    const SourceMark file_mark{graph_.file, 1, 1};
    if (graph_.clock == ClockMode::kStepped && processes_used.size() > 1)
      error(graph_.clock_mark.file.empty() ? file_mark : graph_.clock_mark, "clock",
            "stepped clock runs the graph in one process, but components are placed in " +
                std::to_string(processes_used.size()) + " processes");
  }

  const Graph& graph_;
  const Catalog& catalog_;
  std::vector<Diagnostic>* diags_;
  std::map<std::string, std::vector<PortUse>> writers_, readers_;
  ResolvedGraph out_;
};

}  // namespace

std::string RedactedGraphYaml(const Graph& graph, const ResolvedGraph& resolved) {
  std::string text = graph.yaml_text;
  for (const auto& rc : resolved.components) {
    if (rc.entry == nullptr) continue;
    for (const auto& spec : rc.entry->spec.params()) {
      if (!spec.secret || !rc.params.Has(spec.name)) continue;
      const std::string value = rc.params.String(spec.name);
      if (value.empty()) continue;
      // Only where the value stands whole (`token: s3cret`, `'s3cret'`, `web.token=s3cret`), so a
      // short secret never eats into a name that contains it (token `web`, component `web`).
      auto before_ok = [](char c) { return std::string_view(" \t:'\"{[,=").find(c) != std::string_view::npos; };
      auto after_ok = [](char c) { return std::string_view(" \t\r\n'\",}]#").find(c) != std::string_view::npos; };
      for (size_t at = 0; (at = text.find(value, at)) != std::string::npos;) {
        const size_t end = at + value.size();
        if ((at > 0 && !before_ok(text[at - 1])) || (end < text.size() && !after_ok(text[end]))) {
          at = end;
          continue;
        }
        text.replace(at, value.size(), "<redacted>");
        at += 10;
      }
    }
  }
  return text;
}

ResolvedGraph ValidateGraph(const Graph& graph, const Catalog& catalog, std::vector<Diagnostic>* diags) {
  try {
    return Validation(graph, catalog, diags).Run();
  } catch (const YAML::Exception& e) {  // a node used as what it is not: a problem of the graph, not an abort
    diags->push_back({SourceMark{graph.file, 0, 0}, "", "cannot validate the graph: " + e.msg});
    return ResolvedGraph();
  }
}

}  // namespace dyad
