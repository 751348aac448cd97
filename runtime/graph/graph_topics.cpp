#include "graph/graph_topics.hpp"

#include <algorithm>
#include <set>

#include <dyad/msg/types.hpp>

#include "graph/runtime_topics.hpp"

namespace dyad {

uint64_t ComponentSeed(uint64_t seed, const std::string& name) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : name) h = (h ^ c) * 1099511628211ull;
  uint64_t z = seed + h + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

TopicQos QosOf(const ResolvedTopic& topic) {
  if (topic.config == nullptr) return TopicQos{};
  TopicQos q{topic.config->reliability, topic.config->depth, topic.config->deadline_ms, false};
  q.liveliness_ms = topic.config->liveliness_ms;
  q.ros2_name = topic.config->ros2;
  return q;
}

std::vector<TopicInfo> GraphTopics(const Graph& graph, const ResolvedGraph& resolved, const std::string& process) {
  std::vector<TopicInfo> topics;
  for (const auto& [name, rt] : resolved.topics) {
    TopicInfo t;
    t.name = name;
    t.type = rt.type;
    const TopicQos q = QosOf(rt);
    t.reliable = q.reliability == Reliability::kReliable;
    t.depth = q.depth;
    t.deadline_ms = q.deadline_ms;
    bool all_here = true;
    for (const auto& c : graph.components)
      for (const auto& b : c.outputs)
        if (b.topic == name) {
          t.writers.push_back(c.name + "." + b.port);
          all_here = all_here && graph.ProcessOf(c) == process;
        }
    t.writers_local = !t.writers.empty() && all_here;
    topics.push_back(std::move(t));
  }
  // The runtime's own topics a recorder keeps: every process's timing and live parameter changes,
  // and in a graph of several wall-clock processes their announcements and clock offsets.
  auto add_runtime_topic = [&](const RuntimeTopic& rt, bool writers_local) {
    if (resolved.topics.count(rt.name)) return;
    TopicInfo t;
    t.name = rt.name;
    t.type = &rt.type();
    t.reliable = rt.reader.reliability == Reliability::kReliable;
    t.depth = rt.reader.depth;
    t.writers = {"runtime"};
    t.writers_local = writers_local;
    topics.push_back(std::move(t));
  };
  const bool one_process = graph.ProcessNames().size() == 1;
  add_runtime_topic(runtime_topics::kStats, one_process);  // every process's runtime writes it
  add_runtime_topic(runtime_topics::kParams, one_process);  // live parameter changes, as answered
  if (!one_process && graph.clock == ClockMode::kWall) {
    add_runtime_topic(runtime_topics::kProcesses, false);
    add_runtime_topic(runtime_topics::kClockOffsets, false);
    add_runtime_topic(runtime_topics::kHealth, false);
  }
  std::sort(topics.begin(), topics.end(), [](const TopicInfo& a, const TopicInfo& b) { return a.name < b.name; });
  return topics;
}

}  // namespace dyad
