// dyad/keystore_graph.hpp — the graph a keystore is for: one graph per keystore.
//
// A secured graph's permissions are granted in dyad's partitions (`dyad/*`: the permissions
// document travels in clear, so it does not name the graph) and its participants are admitted by
// the keystore's identity CA. The CA is therefore what keeps graphs apart: a keystore shared by
// two graphs would issue both graphs' identities under one CA, and the identities of one could
// then publish into the other. So a keystore is made for one graph and says which:
//   - `dyad security init` writes kKeystoreGraphFile (the graph's name and a newline, 0600) into
//     the keystore when it has none (a new keystore, or one made before dyad recorded it), and
//     refuses to issue or sign anything for another graph on it (CheckKeystoreGraph);
//   - `dyad security export` copies it into every subset;
//   - CheckKeystore (dyad/security.hpp: `dyad validate`, `dyad run`, the watchers) refuses a graph
//     whose keystore records another graph, and a keystore that records none.
// A renamed graph is another graph: its old identities stay valid under the keystore's CA, so it
// needs a keystore of its own too.
#pragma once

#include <string>

#include <dyad/graph.hpp>
#include <dyad/status.hpp>

namespace dyad {

inline constexpr const char* kKeystoreGraphFile = "graph.name";

// The name of the graph the keystore at `keystore` was made for; "" when it records none (no
// such file, or no such keystore). A record that is a symbolic link, not a regular file, or not
// one name on one line is an error naming the file.
StatusOr<std::string> ReadKeystoreGraph(const std::string& keystore);

// OK when the keystore records no graph or `graph`'s; else FailedPrecondition naming the graph
// the keystore was made for, its record, `graph` and its file, and the fix: a keystore per graph
// (`dyad security init NEW_DIR --graph FILE`).
Status CheckKeystoreGraph(const Graph& graph, const std::string& keystore);

}  // namespace dyad
