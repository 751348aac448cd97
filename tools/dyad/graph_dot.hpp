// tools/dyad/graph_dot.hpp: an experiment graph as a Graphviz picture (`dyad graph`, what
// rqt_graph is to ROS 2).
//
// Contract of GraphDot(graph, resolved):
//   - One box per component: its name, type, and rate ("10 Hz") or trigger ("on state"); one
//     ellipse per topic a port binds or `topics:` declares (bound to no port too): its name and
//     message type. Edges run writer -> topic -> reader, each labelled with its port.
//   - A recorder has a dashed edge "records" from every topic it records (dyad/topic_readers.hpp:
//     its params.topics; none: all); the runtime's own topics it records (dyad/stats, ...) are
//     dashed ellipses labelled "(runtime)".
//   - Processes are clusters ("process mind"); when the graph places processes on hosts, each
//     host is a cluster around its processes, labelled with its address from network.hosts.
//   - Every name is quoted and escaped: any component or topic name gives valid DOT, and the
//     same graph always gives the same text (components, topics and clusters in name order).
#pragma once

#include <string>

#include <dyad/graph.hpp>
#include <dyad/introspect.hpp>
#include <dyad/validate.hpp>

namespace dyad::cli {

std::string GraphDot(const Graph& graph, const ResolvedGraph& resolved);

// Contract of LiveGraphDot(live, graph) (`dyad graph --live`): the running graph as discovered.
//   - One box per participant: a graph process's ("dyad/<graph>/<process>") labelled "process P"
//     with, when `graph` is that graph, the components placed there; any other (a watcher, a
//     guest, another program) by its participant name, dashed.
//   - One ellipse per topic: its name, its type's short name and its measured rate ("49.8 Hz",
//     "no samples", or "rate not measured" for a type this dyad does not know). Edges run writer
//     participant -> topic -> reader participant, one per pair however many endpoints.
//   - Quoting and order as GraphDot's: the same discovery gives the same text.
std::string LiveGraphDot(const LiveGraph& live, const Graph* graph);

}  // namespace dyad::cli
