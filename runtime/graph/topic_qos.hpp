// TopicQos — the quality of service of one endpoint, as the graph declares it (its `topics:`
// entry) or as the runtime chooses for its own topics (graph/runtime_topics.hpp). A plain value:
// the dds layer maps it onto Fast DDS QoS (dds/dds_participant.cpp), the in-memory transport of
// the tests ignores what it cannot model.
#pragma once

#include <string>

#include <dyad/graph.hpp>

namespace dyad {

struct TopicQos {
  Reliability reliability = Reliability::kReliable;
  int depth = 1;
  double deadline_ms = 0;
  bool keep_all = false;         // KEEP_ALL history (recorders); depth then sizes resource limits only
  bool transient_local = false;  // a late-joining reader gets the writer's history (dyad/processes)
  double liveliness_ms = 0;      // > 0: AUTOMATIC liveliness with this lease
  // A ROS 2 topic's name (dyad/ros2_names.hpp): the endpoint is DDS topic "rt<name>" in the
  // default partition. Empty: a dyad topic, under its own name in the run's partition.
  std::string ros2_name{};
};

}  // namespace dyad
