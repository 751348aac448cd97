// What a visitor of running graphs (the watchers `topics/echo/hz/status`, the guests `record` and
// `bag play`) knows and how it joins: the message types of the graph's plugins, its domain,
// network and security.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <dyad/catalog.hpp>
#include <dyad/graph.hpp>
#include <dyad/introspect.hpp>

namespace dyad::cli {

// The catalog a watcher decodes with: the built-in types, DYAD_PLUGIN_PATH, --plugins, and the
// `plugins:` of --graph (so a plugin's own message types are known as the graph knows them).
// Returns false, having said why, when the graph file cannot be read.
// With a graph, the watcher also joins the way the graph's processes do: its domain (unless
// --domain was given) and its network section (static peers, discovery server); a secured
// graph's watcher joins with the identity of this machine's host (`host`, else the machine's
// name; dyad/security.hpp). *watched (if given) receives the graph.
// A tool that may visit as the graph's guest (`as_guest` given: echo, hz, record, pub, bag play)
// joins with the identity `guest` when this machine is none of the graph's hosts and no --host
// was given, and the graph has `security.guests` (it says so on stderr); *as_guest tells it. Without
// the section it is refused, naming the key to add.
bool LoadWatcherCatalog(const std::string& graph_path, std::vector<std::string> plugins, Catalog* catalog,
                        IntrospectOptions* options = nullptr, bool domain_given = false, const std::string& host = "",
                        std::optional<Graph>* watched = nullptr, bool* as_guest = nullptr);

// For a tool that joined `graph` as its guest: true when security.guests.subscribe grants every
// one of `topics`; else false, having said for each topic refused which key to change and which
// init to rerun (`graph_path` as the user gave it).
bool GuestMayRead(const Graph& graph, const std::string& graph_path, const std::vector<std::string>& topics,
                  const std::string& tool);

}  // namespace dyad::cli
