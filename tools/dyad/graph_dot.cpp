#include "graph_dot.hpp"

#include <dyad/topic_readers.hpp>

#include <map>
#include <set>
#include <sstream>

namespace dyad::cli {
namespace {

// A DOT string literal.
std::string Quoted(const std::string& s) {
  std::string q = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') q += '\\';
    if (c == '\n') {
      q += "\\n";
      continue;
    }
    q += c;
  }
  return q + "\"";
}

std::string ComponentId(const std::string& name) { return Quoted("c:" + name); }
std::string TopicId(const std::string& name) { return Quoted("t:" + name); }

std::string Rate(const ComponentConfig& c) {
  if (!c.trigger.empty()) return "on " + c.trigger;
  std::ostringstream r;
  r << c.rate_hz << " Hz";
  return r.str();
}

void Component(const ComponentConfig& c, const std::string& indent, std::ostream& out) {
  out << indent << ComponentId(c.name) << " [shape=box, style=\"rounded,filled\", fillcolor=\"#dde8f5\", label="
      << Quoted(c.name + "\n" + c.type + "\n" + Rate(c)) << "];\n";
}

}  // namespace

std::string GraphDot(const Graph& graph, const ResolvedGraph& resolved) {
  std::ostringstream out;
  out << "digraph " << Quoted(graph.name) << " {\n"
      << "  rankdir=LR;\n  fontname=\"Helvetica\";\n  node [fontname=\"Helvetica\", fontsize=11];\n"
      << "  edge [fontname=\"Helvetica\", fontsize=9, color=\"#555555\"];\n"
      << "  label=" << Quoted("graph " + graph.name + " (" + (graph.clock == ClockMode::kStepped ? "stepped" : "wall clock") + ")")
      << ";\n  labelloc=t;\n";
  // host -> process -> components, in name order ("" host: the graph places none).
  std::map<std::string, std::map<std::string, std::vector<const ComponentConfig*>>> placed;
  for (const auto& c : graph.components) {
    const std::string process = graph.ProcessOf(c);
    const ProcessConfig* p = graph.FindProcess(process);
    placed[p != nullptr ? p->host : ""][process].push_back(&c);
  }
  const bool several_processes = graph.ProcessNames().size() > 1;
  for (const auto& [host, processes] : placed) {
    std::string indent = "  ";
    if (!host.empty()) {
      auto address = graph.network.hosts.find(host);
      out << indent << "subgraph " << Quoted("cluster_host_" + host) << " {\n"
          << indent << "  label=" << Quoted("host " + host + (address != graph.network.hosts.end() ? " (" + address->second + ")" : ""))
          << ";\n" << indent << "  style=dashed;\n";
      indent += "  ";
    }
    for (const auto& [process, components] : processes) {
      if (several_processes || !host.empty()) {
        out << indent << "subgraph " << Quoted("cluster_process_" + process) << " {\n"
            << indent << "  label=" << Quoted("process " + process) << ";\n" << indent << "  style=\"rounded\";\n";
      }
      for (const ComponentConfig* c : components) Component(*c, indent + (several_processes || !host.empty() ? "  " : ""), out);
      if (several_processes || !host.empty()) out << indent << "}\n";
    }
    if (!host.empty()) out << "  }\n";
  }
  // Every topic a port binds or `topics:` declares (bound to no port or not), and what recorders
  // record (the runtime's own topics too: drawn dashed).
  std::set<std::string> topics;
  for (const auto& c : graph.components) {
    for (const auto& b : c.outputs)
      if (!b.topic.empty()) topics.insert(b.topic);
    for (const auto& b : c.inputs)
      if (!b.topic.empty()) topics.insert(b.topic);
  }
  for (const auto& t : graph.topics) topics.insert(t.name);
  for (const auto& [name, t] : resolved.topics) topics.insert(name);
  std::map<std::string, std::vector<std::string>> recorded;  // recorder -> its topics
  for (const auto& c : graph.components)
    if (c.type == "recorder") recorded[c.name] = RecordedTopics(graph, resolved, c);
  std::set<std::string> runtime_only;
  for (const auto& [recorder, names] : recorded)
    for (const auto& t : names)
      if (!topics.count(t)) runtime_only.insert(t);
  for (const auto& t : topics) {
    auto r = resolved.topics.find(t);
    const std::string type = r != resolved.topics.end() && r->second.type != nullptr ? r->second.type->short_name() : "?";
    out << "  " << TopicId(t) << " [shape=ellipse, label=" << Quoted(t + "\n" + type) << "];\n";
  }
  for (const auto& t : runtime_only)
    out << "  " << TopicId(t) << " [shape=ellipse, style=dashed, label=" << Quoted(t + "\n(runtime)") << "];\n";
  for (const auto& c : graph.components) {
    for (const auto& b : c.outputs)
      if (!b.topic.empty()) out << "  " << ComponentId(c.name) << " -> " << TopicId(b.topic) << " [label=" << Quoted(b.port) << "];\n";
    for (const auto& b : c.inputs)
      if (!b.topic.empty()) out << "  " << TopicId(b.topic) << " -> " << ComponentId(c.name) << " [label=" << Quoted(b.port) << "];\n";
    auto rec = recorded.find(c.name);
    if (rec == recorded.end()) continue;
    for (const auto& t : rec->second)
      out << "  " << TopicId(t) << " -> " << ComponentId(c.name) << " [label=\"records\", style=dashed];\n";
  }
  out << "}\n";
  return out.str();
}

namespace {

// "process mind" (+ its components) for a process of `graph`; else the participant's name.
std::string ParticipantLabel(const std::string& participant, const Graph* graph, bool* of_graph) {
  *of_graph = false;
  if (graph == nullptr) return participant;
  const std::string prefix = "dyad/" + graph->name + "/";
  if (participant.rfind(prefix, 0) != 0) return participant;
  const std::string process = participant.substr(prefix.size());
  if (!graph->ProcessNames().count(process)) return participant;
  *of_graph = true;
  std::string label = "process " + process;
  for (const auto& c : graph->components)
    if (graph->ProcessOf(c) == process) label += "\n" + c.name + " (" + c.type + ")";
  return label;
}

std::string RateText(const LiveGraph& live, const std::string& topic) {
  auto r = live.rates_hz.find(topic);
  if (r == live.rates_hz.end()) return "rate not measured";
  if (r->second <= 0) return "no samples";
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(1);
  text << r->second << " Hz";
  return text.str();
}

}  // namespace

std::string LiveGraphDot(const LiveGraph& live, const Graph* graph) {
  std::ostringstream out;
  out << "digraph " << Quoted(graph ? graph->name + " (live)" : "live") << " {\n"
      << "  rankdir=LR;\n  fontname=\"Helvetica\";\n  node [fontname=\"Helvetica\", fontsize=11];\n"
      << "  edge [fontname=\"Helvetica\", fontsize=9, color=\"#555555\"];\n";
  std::set<std::string> participants;
  std::map<std::string, std::string> types;  // topic -> type (short name)
  std::set<std::pair<std::string, std::string>> writes, reads;  // (participant, topic)
  for (const auto& e : live.endpoints) {
    participants.insert(e.participant);
    const std::string type = e.type.substr(0, e.type.find('#'));
    types.emplace(e.topic, type.substr(type.rfind(':') == std::string::npos ? 0 : type.rfind(':') + 1));
    (e.writer ? writes : reads).insert({e.participant, e.topic});
  }
  for (const auto& p : participants) {
    bool of_graph = false;
    const std::string label = ParticipantLabel(p, graph, &of_graph);
    out << "  " << Quoted("p:" + p) << " [shape=box, style=" << (of_graph ? "\"rounded,filled\", fillcolor=\"#dde8f5\"" : "dashed")
        << ", label=" << Quoted(label) << "];\n";
  }
  for (const auto& [topic, type] : types)
    out << "  " << TopicId(topic) << " [shape=ellipse, label=" << Quoted(topic + "\n" + type + "\n" + RateText(live, topic)) << "];\n";
  for (const auto& [p, topic] : writes) out << "  " << Quoted("p:" + p) << " -> " << TopicId(topic) << ";\n";
  for (const auto& [p, topic] : reads) out << "  " << TopicId(topic) << " -> " << Quoted("p:" + p) << ";\n";
  out << "}\n";
  return out.str();
}

}  // namespace dyad::cli
