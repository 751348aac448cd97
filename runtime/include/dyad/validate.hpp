// dyad/validate.hpp — checks a graph against the available component types before anything runs.
//
// Reports every problem at once (file:line:col: key: message): unknown component types, unknown
// or missing or mistyped or out-of-range params, unknown ports, inputs bound to a topic that no
// component publishes (unless `topics:` declares it with a type: published from outside the ports,
// e.g. by a replay), required inputs left unbound, topic type mismatches (between writer and
// reader ports, and against the type declared under `topics:`), rates that are not positive, a
// component with neither rate_hz nor trigger, processes that are not declared, stepped clock
// across several processes; warns (ResolvedGraph::warnings) about outputs bound to no topic and
// declared topics that no component writes; and then, with DryConfigure, whatever each component's own
// Configure() would reject.
#pragma once

#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <dyad/catalog.hpp>
#include <dyad/graph.hpp>
#include <dyad/params.hpp>

namespace dyad {

struct ResolvedComponent {
  const ComponentConfig* config = nullptr;  // into the Graph
  const CatalogEntry* entry = nullptr;      // into the Catalog
  Params params;
  int64_t period_ns = 0;  // 0: triggered
};

struct ResolvedTopic {
  const TopicConfig* config = nullptr;  // null: not declared under topics:, defaults apply
  const TypeInfo* type = nullptr;
  std::string name;
};

struct ResolvedGraph {
  std::vector<ResolvedComponent> components;   // graph order
  // Every topic some port binds, and every topic declared under `topics:` with a known type.
  std::map<std::string, ResolvedTopic> topics;
  // Legal wiring that is likely a hole: an output bound to no topic, a topic declared under
  // `topics:` that no component writes. `dyad validate` and a launcher print them, prefixed
  // "warning: "; they never stop a run.
  std::vector<Diagnostic> warnings;
};

// Appends problems to *diagnostics; the result is complete only when none were added.
ResolvedGraph ValidateGraph(const Graph& graph, const Catalog& catalog, std::vector<Diagnostic>* diagnostics);

// Runs every component's Configure() against a dry context (no DDS, nothing started) and adds a
// diagnostic for each that fails, placed at the param its message names (the element inside a
// structured param, or the --set) or at the component. Components with problems of their own in
// *diagnostics are skipped (their params are incomplete). Relies on component.hpp's contract:
// Configure acts on nothing. See runtime/graph/dry_configure.cpp.
// With `only_processes` (empty: all), only the components placed in those processes are
// configured: a process started on its own (a launcher's child, or `--process` on another host)
// and a launcher of one host (`--host`) check what they will run, not the files of processes on
// other machines, which live there or are already in use (a recorder's file, created by its own
// process on a shared folder, "exists").
void DryConfigure(const Graph& graph, const ResolvedGraph& resolved, const Catalog& catalog,
                  std::vector<Diagnostic>* diagnostics, const std::set<std::string>& only_processes = {});

// The topics one process's components read and write: their bound ports, and what their
// Configure subscribes (SubscribeSerialized, on demand or not) and advertises
// (AdvertiseSerialized), as the dry context sees it. The runtime's own dyad/ topics are not in
// it. What DDS Security's permissions of each process grant (`dyad security init`).
struct TopicAccess {
  std::set<std::string> reads, writes;
};
// DryConfigure of every component, collecting each process's TopicAccess (every process that
// runs a component has an entry). Diagnostics as DryConfigure's.
std::map<std::string, TopicAccess> TopicAccessByProcess(const Graph& graph, const ResolvedGraph& resolved,
                                                         const Catalog& catalog, std::vector<Diagnostic>* diagnostics);

// The graph's text (Graph::yaml_text) with the value of every Secret() param of its components
// replaced by "<redacted>" wherever it stands as a whole value (the param, a --set in the header
// of a graph as run; never inside a longer word): what Context::graph_yaml() gives components,
// and recorders keep.
std::string RedactedGraphYaml(const Graph& graph, const ResolvedGraph& resolved);

// Converts a YAML value to a param of `spec`'s type; InvalidArgument (message without location)
// when it is not one.
StatusOr<ParamValue> ParamFromYaml(const ParamSpec& spec, const YAML::Node& node);

// A path param's value (a string or a list of strings) made absolute against `base` (the graph
// file's folder); absolute and empty values are kept.
void ResolvePaths(const std::filesystem::path& base, ParamValue* value);

}  // namespace dyad
