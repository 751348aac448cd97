#include "graph_dot.hpp"

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
  std::set<std::string> topics;
  for (const auto& c : graph.components) {
    for (const auto& b : c.outputs)
      if (!b.topic.empty()) topics.insert(b.topic);
    for (const auto& b : c.inputs)
      if (!b.topic.empty()) topics.insert(b.topic);
  }
  for (const auto& t : topics) {
    auto r = resolved.topics.find(t);
    const std::string type = r != resolved.topics.end() && r->second.type != nullptr ? r->second.type->short_name() : "?";
    out << "  " << TopicId(t) << " [shape=ellipse, label=" << Quoted(t + "\n" + type) << "];\n";
  }
  for (const auto& c : graph.components) {
    for (const auto& b : c.outputs)
      if (!b.topic.empty()) out << "  " << ComponentId(c.name) << " -> " << TopicId(b.topic) << " [label=" << Quoted(b.port) << "];\n";
    for (const auto& b : c.inputs)
      if (!b.topic.empty()) out << "  " << TopicId(b.topic) << " -> " << ComponentId(c.name) << " [label=" << Quoted(b.port) << "];\n";
  }
  out << "}\n";
  return out.str();
}

}  // namespace dyad::cli
