// Who a graph declares reads a topic (dyad/topic_readers.hpp).
#include "dyad/topic_readers.hpp"

#include <optional>

#include <dyad/topic_select.hpp>

#include "graph/graph_topics.hpp"

namespace dyad {

namespace {

// params.topics as written: nullopt when it is not a list of strings (validation says so).
std::optional<std::vector<std::string>> TopicPatterns(const YAML::Node& params) try {
  std::vector<std::string> patterns;
  const YAML::Node list = params.IsDefined() && params.IsMap() ? params["topics"] : YAML::Node();
  if (!list.IsDefined() || list.IsNull()) {
    // none: every topic
  } else if (list.IsSequence()) {
    for (const auto& entry : list) {
      if (!entry.IsScalar()) return std::nullopt;
      patterns.push_back(entry.as<std::string>());
    }
  } else {
    return std::nullopt;
  }
  return patterns;
} catch (const YAML::Exception&) {
  return std::nullopt;
}

}  // namespace

std::vector<std::string> RecordedTopics(const Graph& graph, const ResolvedGraph& resolved, const ComponentConfig& c) {
  const auto patterns = TopicPatterns(c.params);
  if (!patterns) return {};
  std::vector<std::string> names;
  for (const TopicInfo& t : GraphTopics(graph, resolved, graph.ProcessOf(c))) names.push_back(t.name);
  auto chosen = SelectTopics(*patterns, names, "params.topics");
  return chosen.ok() ? chosen.value() : std::vector<std::string>{};
}

std::vector<DeclaredReader> DeclaredReaders(const Graph& graph, const ResolvedGraph& resolved, const std::string& topic) {
  std::vector<DeclaredReader> readers;
  for (const auto& c : graph.components) {
    for (const auto& b : c.inputs)
      if (b.topic == topic) readers.push_back({&c, DeclaredReader::kPort, b.port});
    if (c.type != "recorder" && c.type != "web") continue;
    for (const std::string& t : RecordedTopics(graph, resolved, c))
      if (t == topic) readers.push_back({&c, c.type == "recorder" ? DeclaredReader::kRecorder : DeclaredReader::kWeb, ""});
  }
  return readers;
}

}  // namespace dyad
