// dyad/topic_readers.hpp — who in a graph reads a topic, as the graph file declares it: what
// `dyad graph` draws and `dyad pub --graph` waits for.
//
// Contract of DeclaredReaders(graph, resolved, topic): in graph order,
//   - every component with an input port bound to `topic` (kind kPort, `port` its name);
//   - every `recorder` component whose params.topics choose `topic` (kind kRecorder);
//   - every `web` component whose params.topics choose it (kind kWeb): its Foxglove bridge reads
//     the topic only while a page subscribes to it, so it is a reader that may be absent.
// params.topics choose as the component itself does (dyad/topic_select.hpp: names or whole-name
// regular expressions over the graph's topics and the runtime's own; none: every topic); a bad
// list chooses nothing here (validation reports it).
// RecordedTopics(graph, resolved, c): the topics a recorder (or web) component `c` chooses, in
// name order. Pure functions of their arguments.
#pragma once

#include <string>
#include <vector>

#include <dyad/graph.hpp>
#include <dyad/validate.hpp>

namespace dyad {

struct DeclaredReader {
  enum Kind { kPort, kRecorder, kWeb };
  const ComponentConfig* component = nullptr;
  Kind kind = kPort;
  std::string port;  // kPort: the input port; else empty
};

std::vector<DeclaredReader> DeclaredReaders(const Graph& graph, const ResolvedGraph& resolved, const std::string& topic);
std::vector<std::string> RecordedTopics(const Graph& graph, const ResolvedGraph& resolved, const ComponentConfig& c);

}  // namespace dyad
