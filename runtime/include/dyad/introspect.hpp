// dyad/introspect.hpp — looking at a running experiment from outside: `dyad topics`,
// `dyad echo`, `dyad hz`, `dyad status`. Each joins the DDS domain as a guest participant (UDP only, BEST_EFFORT
// readers, no shared memory): whatever a watcher does or however it dies (SIGKILL, `| head`),
// the graph's writers never wait for it.
//
// Ctrl-C (or SIGTERM) ends them cleanly (participant deleted, so the graph forgets it at once)
// with exit 0: it is how `echo` and `hz` without a count or duration are meant to end. A closed
// output (`dyad echo T | head -2`) ends them the same way, quietly, exit 0 (SIGPIPE is ignored by
// the dyad executable, so the write fails instead of killing the process).
//
// Types are resolved from the topic's discovered DDS type name ("name#hash") against the
// message types this dyad knows (built-in IDL and loaded plugins). A topic whose type has the
// same IDL name but another hash was built from another IDL version: reported, not read.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <map>
#include <string>
#include <vector>

#include <dyad/catalog.hpp>
#include <dyad/graph.hpp>
#include <dyad/security.hpp>

namespace dyad {

struct IntrospectOptions {
  int domain_id = 0;
  // Discovery time before answering (topics) or giving up on a topic (echo, hz: they start as
  // soon as a writer is found, typically after ~0.2 s). Fast DDS occasionally loses its first
  // discovery exchange and repeats it only at the next announcement (up to 3 s): 5 s covers it.
  double wait_s = 5.0;
  // How to find the graph's processes: its network section (`--graph`; default: multicast).
  NetworkConfig network;
  // Which runs to watch (each run is a DDS partition, see docs/runtime.md): empty graph_name:
  // every dyad run on the domain; a name: that graph's runs; with run_id: that run only.
  std::string graph_name;
  std::string run_id;
  // A secured graph's (dyad/security.hpp): the identity of this machine's host; none: no security.
  IdentityFiles security;
};

// Given the graph (`--graph`), a watcher ends as soon as it has seen what the graph says should
// be there; `wait_s` is then only an upper bound (what it has not seen by then is said).

// Prints one line per topic: name, type, writers, readers, participants. Returns 0, or 1 when
// nothing was found. With `graph`: ends once every topic its components bind has a writer (when
// a component writes it) and a reader (when one reads it), and every process's participant was
// discovered, plus 0.2 s for the rest of that discovery burst.
int ListTopics(const IntrospectOptions& options, std::ostream& out, const Graph* graph = nullptr);

// `dyad graph --live`: the running graphs as discovered (every other participant's writers and
// readers; the runtime's own dyad/... topics left out) and each topic's rate measured over
// `listen_s` seconds by a best-effort reader (topics whose type this dyad knows). Discovery ends
// as ListTopics' does: with `graph`, once its topics and processes are found (`wait_s` at most).
// Returns 0, or 1 when nothing was found.
struct LiveGraph {
  struct Endpoint {
    std::string participant, topic, type;
    bool writer = false;
  };
  std::vector<Endpoint> endpoints;
  std::map<std::string, double> rates_hz;  // per topic; absent: not measured (type unknown)
};
int DiscoverLiveGraph(const IntrospectOptions& options, const Catalog& catalog, const Graph* graph, double listen_s,
                      LiveGraph* live, std::ostream& err);

// Turns one serialized sample (CDR with encapsulation) of `type` into text.
using SamplePrinter = std::function<std::string(const TypeInfo& type, const uint8_t* data, size_t size)>;

// Prints `count` samples (0: until SIGINT or `duration_s`), one per line.
int EchoTopic(const IntrospectOptions& options, const Catalog& catalog, const std::string& topic, uint64_t count,
              double duration_s, const SamplePrinter& printer, std::ostream& out, std::ostream& err);

// Prints the receive rate every second (rate, mean/min/max period, samples) for `duration_s`
// (0: until SIGINT); returns 1 if no sample arrived.
int TopicHz(const IntrospectOptions& options, const Catalog& catalog, const std::string& topic, double duration_s,
            std::ostream& out, std::ostream& err);

// `dyad status`: listens to dyad/processes, dyad/stats and dyad/clock_offsets (all three keep
// their last samples for a late joiner), then prints every process of `graph` (null: of every
// graph on the domain, listening `wait_s`) with its host, pid, state and restarts, the clock
// offsets the processes measured of each other, and each component's step statistics. With a
// graph it ends once it has heard every process, the step statistics of every component of the
// running ones, and the offsets between every two processes running for 3 s (they are measured
// every 2 s), plus 0.15 s for the rest of that burst. Returns 0, or 1 when no process was heard.
int ShowStatus(const IntrospectOptions& options, const Graph* graph, std::ostream& out, std::ostream& err);

}  // namespace dyad
