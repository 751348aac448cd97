// What a process's components see of the graph, computed the same way for a run (Executor) and
// for validation's dry configure (dry_configure.cpp): every topic with its type and QoS, each
// component's seed. Internal to the runtime.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <dyad/component.hpp>
#include <dyad/validate.hpp>

#include "graph/topic_qos.hpp"

namespace dyad {

// The graph's seed mixed with a component name (splitmix64): stable across runs and platforms.
uint64_t ComponentSeed(uint64_t graph_seed, const std::string& name);
// QoS from the graph's `topics:` entry, defaults when the topic is not declared there.
TopicQos QosOf(const ResolvedTopic& topic);
// Context::graph_topics() for the components of `process`: every topic of the graph, sorted by
// name, with the runtime's own topics that a recorder may keep (graph/runtime_topics.hpp).
std::vector<TopicInfo> GraphTopics(const Graph& graph, const ResolvedGraph& resolved, const std::string& process);

}  // namespace dyad
