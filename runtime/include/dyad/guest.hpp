// dyad/guest.hpp — visiting running graphs: `dyad record` runs a recorder and `dyad bag play` a
// replay as a guest of the watched graph's runs (RunGuest); `dyad pub` publishes samples on one of
// its topics (PublishTopic); `dyad param get|set` asks for a live parameter (RequestParam). A guest is a one-process graph
// of its own components whose topics are the watched graph's (types and QoS as its graph file
// says), or, without a graph file, the topics as discovered.
//
// A guest joins as the watchers do (introspect.hpp): the watched graph's domain, network and
// security (this host's identity), UDP only with no shared memory (whatever the guest does or
// however it dies, the graph's writers never wait for it), and the partitions of every run of
// the graph (or of one run, `run_id`). It is none of the graph's processes: it announces nothing
// on dyad/processes (`dyad status` does not list it, no start barrier waits for it) and publishes
// no step statistics on dyad/stats. Its clock is the wall clock (stepped runs keep their DDS to
// their own process: there is nothing to visit).
//
// Before its components are activated, the guest waits, up to `watch.wait_s`, until its readers
// of every topic of `await_writers` are matched with that topic's writers, and its writers of
// every topic of `await_readers` with that topic's readers (every one discovered in its
// partitions, at least one), so that what it records or plays starts with the graph's first
// sample, not with a discovery race; what it has not matched by then is said, and it goes on.
// Discovery is not symmetric (a graph reader may match the guest's writer a moment after the
// writer matched it): a guest with writers waits 0.5 s more before its first sample, and its
// reliable volatile writers keep their last 100 samples whatever the topic's depth, so a reader
// later still gets up to 100 first samples by repair (late) instead of losing them.
//
// Returns as RunGraph does (run.hpp): 0 at a clean end (a component's RequestStop, `duration_s`,
// SIGINT/SIGTERM: 0 too, since that is how a recording ends), 2 for a bad guest graph or a topic
// whose type cannot be found, 1 for a failure while running. No timing table is printed.
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include <dyad/catalog.hpp>
#include <dyad/graph.hpp>
#include <dyad/introspect.hpp>
#include <dyad/status.hpp>

namespace dyad {

struct GuestOptions {
  // Domain, network, security, graph name and run to join (LoadWatcherCatalog fills it from
  // --graph).
  IntrospectOptions watch;
  // The watched graph (its topics' types and QoS); null: `discover` names the topics, whose types
  // are those of their discovered writers (up to watch.wait_s).
  const Graph* watched = nullptr;
  std::vector<std::string> discover;
  // The guest's components: the `components:` mapping of a graph file, as YAML text.
  std::string components_yaml;
  // Where the guest's components come from in messages ("dyad record", "dyad bag play").
  std::string label = "guest";
  std::vector<std::string> await_writers, await_readers;
  double duration_s = 0;  // > 0: stop after this much wall time
};

int RunGuest(const GuestOptions& options, const Catalog& catalog, std::ostream& out, std::ostream& err);

// `dyad pub`: a guest (joined as above) that writes `count` samples on `topic` (0: until
// SIGINT/SIGTERM), `rate_hz` apart (0: back to back). The topic's type and QoS are the watched
// graph's; without a graph, `type_name` names it ("HumanInput" or "dyad::msg::HumanInput"), else
// it is the type of the topic's discovered endpoints (readers or writers, up to watch.wait_s).
// Sample 0 is made before anything is published: a bad sample publishes nothing. The first
// sample waits, up to watch.wait_s, for the topic's readers in the graph's processes that read it
// (with a graph; else any reader) and until the writer has matched every reader discovered in
// its partitions; then it is published anyway, with a warning. At the end each sample has been
// acknowledged by the reliable readers, or 0.5 s has passed.
// Returns 0, 2 for bad input (an unknown topic or type, a bad sample: said on `err`), 1 when a
// write fails, 128 + signal when a signal ended a run with a `count` it did not reach.
struct PublishOptions {
  IntrospectOptions watch;
  const Graph* watched = nullptr;
  std::string topic;
  std::string type_name;
  uint64_t count = 1;
  double rate_hz = 0;
};
// Sample `index` (0-based) of `type`: CDR with its encapsulation header, or why not.
using SampleMaker = std::function<StatusOr<std::vector<uint8_t>>(const TypeInfo& type, uint64_t index)>;
int PublishTopic(const PublishOptions& options, const Catalog& catalog, const SampleMaker& make_sample, std::ostream& out,
                 std::ostream& err);

// `dyad param get|set`: asks the process that runs `component` of the watched graph for the value
// of its live parameter `param`, or (with `value`, YAML text) to change it, and waits up to
// watch.wait_s for its answer (the component answers at its next step boundary). Checked against
// the graph file first: the component, the parameter, that it is live and that the value fits its
// declaration (an error names what is wrong: exit 2, nothing asked). It waits, within the same
// bound, for the process's endpoints of dyad/param_requests and dyad/params.
// Prints "COMPONENT.PARAM: OLD -> NEW (step N)" or "COMPONENT.PARAM: VALUE"; returns 0, 1 when the
// process refused (its reason said) or did not answer, 2 for bad input.
struct ParamRequest {
  IntrospectOptions watch;
  const Graph* watched = nullptr;  // required
  std::string component, param;
  bool set = false;
  std::string value;  // with `set`
  std::string who;    // who asks, as recorded ("dyad param (ana@lab-pc)")
};
int RequestParam(const ParamRequest& request, const Catalog& catalog, std::ostream& out, std::ostream& err);

}  // namespace dyad
