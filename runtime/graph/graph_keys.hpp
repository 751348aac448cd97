// The keys of each section of a graph file, in one place: the reader (graph.cpp) allows exactly
// these and reports any other with the list, and --set (graph_document.cpp) places an override
// by them. A key added to the format is added here once, and both know it.
#pragma once

#include <set>
#include <string>

namespace dyad::graph_keys {

// The graph's own scalars: settable by their name alone (`--set seed=3`).
inline const std::set<std::string> kScalars = {"graph", "domain_id", "clock", "seed", "plugins", "logs"};
inline const std::set<std::string> kTopLevel = {"graph",   "domain_id", "clock",     "seed",   "plugins",
                                                "logs",    "network",   "security",  "processes", "topics", "components"};
inline const std::set<std::string> kSecurity = {"keystore", "guests"};
inline const std::set<std::string> kSecurityGuests = {"publish", "subscribe"};
inline const std::set<std::string> kNetwork = {"scope", "discovery", "hosts",   "peers",           "server",
                                               "transport", "interfaces", "lease_s",       "start_timeout_s",
                                               "max_clock_offset_ms", "launcher_tcp_port"};
inline const std::set<std::string> kProcess = {"host", "restart", "max_restarts", "backoff_s", "required", "tcp_port"};
inline const std::set<std::string> kTopic = {"type", "reliability", "depth", "deadline_ms", "liveliness_ms", "ros2", "qos"};
// A component's scalars (`--set mixer.rate_hz=20`); its params, inputs and outputs are maps.
inline const std::set<std::string> kComponentScalars = {"type", "rate_hz", "trigger", "process"};
inline const std::set<std::string> kComponent = {"type", "rate_hz", "trigger", "process", "params", "inputs", "outputs"};

}  // namespace dyad::graph_keys
