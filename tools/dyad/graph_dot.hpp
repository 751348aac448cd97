// tools/dyad/graph_dot.hpp: an experiment graph as a Graphviz picture (`dyad graph`, what
// rqt_graph is to ROS 2).
//
// Contract of GraphDot(graph, resolved):
//   - One box per component: its name, type, and rate ("10 Hz") or trigger ("on state"); one
//     ellipse per topic a port binds: its name and message type. Edges run writer -> topic ->
//     reader, each labelled with its port.
//   - Processes are clusters ("process mind"); when the graph places processes on hosts, each
//     host is a cluster around its processes, labelled with its address from network.hosts.
//   - Every name is quoted and escaped: any component or topic name gives valid DOT, and the
//     same graph always gives the same text (components, topics and clusters in name order).
#pragma once

#include <string>

#include <dyad/graph.hpp>
#include <dyad/validate.hpp>

namespace dyad::cli {

std::string GraphDot(const Graph& graph, const ResolvedGraph& resolved);

}  // namespace dyad::cli
