// The DDS Security documents of a graph (OMG DDS Security 1.1, as Fast DDS 2.9 reads them): the
// governance of the domain and each identity's permissions, as XML (signed by keystore.cpp).
//
// Governance: participants without an identity from the graph's CA are refused; discovery,
// liveliness and every topic's metadata and data are encrypted; reads and writes are checked
// against the permissions.
// Permissions (default DENY), in dyad's partitions (dyad/*: a graph's runs are dyad/<graph>/<run>;
// the partition does not name the graph, since the document travels in clear in every handshake,
// and the graph's own identity CA already keeps other graphs' participants out):
//   process.<p>  publishes what its components write and the runtime's dyad/ topics a process
//                writes; subscribes to what its components read (ports, and the recorder's and
//                web component's subscriptions) and the dyad/ topics a process reads.
//   host.<h>     the launcher publishes dyad/launchers and dyad/processes; it and the host's
//                watchers (dyad status, echo, hz) subscribe to every topic.
// Domains: any (0..232): the identity CA, not the domain id, says which graph a participant is in.
// Nothing in a document names the graph, a process or a host: the grant is named "grant" and its
// subject is the certificate's, opaque (dyad/wire_names.hpp). What remains readable is the topic
// names and the validity dates.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include <dyad/graph.hpp>
#include <dyad/validate.hpp>

namespace dyad::cli {

std::string GovernanceXml();

// `subject`: the identity certificate's subject ("CN=..."); `not_before` / `not_after`: the
// grant's validity, "YYYY-MM-DDThh:mm:ss" UTC.
std::string PermissionsXml(const Graph& graph, const std::string& identity, const std::string& subject,
                           const std::map<std::string, TopicAccess>& access, const std::string& not_before,
                           const std::string& not_after);

}  // namespace dyad::cli
