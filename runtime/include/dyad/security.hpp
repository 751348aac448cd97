// dyad/security.hpp — DDS Security from the graph: the keystore's layout and its checks.
//
// A graph with a `security:` section runs every DDS participant it makes (each process's, each
// launcher's, each watcher's) with DDS Security: Fast DDS's builtin.PKI-DH authentication,
// builtin.Access-Permissions access control and builtin.AES-GCM-GMAC encryption. A participant
// without an identity from the graph's identity CA is not let in (it discovers nothing and
// receives nothing), and each participant may publish and subscribe only what its permissions
// document grants. docs/security.md says what that protects and what it does not.
//
//   security:
//     keystore: keys/demo      # made by `dyad security init keys/demo --graph GRAPH`
//
// The keystore (relative paths are relative to the graph file):
//   identity_ca.cert.pem, permissions_ca.cert.pem   the two CAs' certificates
//   governance.xml, governance.p7s                  the domain's rules, signed by the permissions CA
//   ca/identity_ca.key.pem, ca/permissions_ca.key.pem
//                                                   the CAs' keys: `dyad security` needs them to
//                                                   issue identities; runs do not (keep them off
//                                                   the experiment machines)
//   identities/<identity>/cert.pem, key.pem, permissions.xml, permissions.p7s
//   graph.name                                      the graph the keystore is for: one graph per
//                                                   keystore (dyad/keystore_graph.hpp)
// Identities: "process.<p>" for each process of the graph (its participant is dyad/<graph>/<p>)
// and "host.<h>" for each host's launcher and watchers ("host.local" when the graph places
// nothing on hosts), and "guest" when the graph has `security.guests`: the identity of `dyad pub`
// and `dyad bag play` in a secured graph, allowed to publish `guests.publish` and read
// `guests.subscribe`, nothing else of the graph's. IdentitySubject gives each its readable
// subject (CN=dyad/<graph>/<p>, CN=dyad/<graph>/host/<h>, CN=dyad/<graph>/guest/tools: no
// process or host has that shape); its certificate and permissions grant carry the opaque form,
// CN=WireSubject(key, the name after CN=), with the keystore's names.key (dyad/wire_names.hpp).
//
// Loading a graph checks the keystore (CheckKeystore): every identity the graph needs is there,
// no private key is readable by others or a symbolic link, every certificate is valid now. Fast
// DDS 2.9 has no secure discovery server, so `discovery: server` with security is refused.
//
// A keystore subset (`dyad security export`, tools/dyad/keystore_export.hpp) is what one machine
// of the graph holds: the CA certificates (no CA key), the governance, names.key and only that
// machine's identities, with subset.yaml saying whom it is for (`host: H`: H's host identity and
// the processes the graph places on H or on no host; `guest: true`: the guest identity; both
// together: both). CheckKeystore then checks only those identities, and whatever needs another
// identity (a process, a launcher, a tool) is refused by CheckIdentityHeld, naming the identity,
// whom the subset is for, and the export that would give it. A keystore without subset.yaml is
// whole: every identity is checked, as before.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <dyad/graph.hpp>
#include <dyad/status.hpp>

namespace dyad {

// The files one participant's DDS Security needs (all absolute paths; empty keystore: none).
struct IdentityFiles {
  std::string identity_ca;     // the identity CA's certificate
  std::string certificate;     // this identity's certificate, issued by the identity CA
  std::string private_key;     // its key (0600)
  std::string permissions_ca;  // the permissions CA's certificate
  std::string governance;      // governance.p7s
  std::string permissions;     // this identity's permissions.p7s
  bool enabled() const { return !certificate.empty(); }
};

inline constexpr const char* kLocalHost = "local";
inline constexpr const char* kGuestIdentity = "guest";

// True when `topic` is one of `grants` (names, or fnmatch patterns as DDS Security matches them).
bool TopicGranted(const std::vector<std::string>& grants, const std::string& topic);

std::string ProcessIdentity(const std::string& process);  // "process.<p>"
std::string HostIdentity(const std::string& host);        // "host.<h>"
// The hosts whose launchers and watchers get an identity: every host a process is placed on,
// and those of network.hosts; {kLocalHost} for a graph on one machine.
std::vector<std::string> IdentityHosts(const Graph& graph);
// Every identity the graph needs: its processes', then its hosts', then the guest's (if any).
std::vector<std::string> GraphIdentities(const Graph& graph);
// The readable subject of an identity ("CN=dyad/<graph>/..."); its certificate and permissions
// grant carry its opaque form (dyad/wire_names.hpp), never this.
std::string IdentitySubject(const Graph& graph, const std::string& identity);

// The files of `identity` in the graph's keystore (nothing when the graph has no security).
IdentityFiles IdentityOf(const Graph& graph, const std::string& identity);
// The identity a watcher or a launcher on `host` uses: host.<host> when the graph knows that
// host, else host.local when it places nothing on hosts, else the only host identity there is;
// NotFound otherwise, saying exactly what to pass ("--host lab or --host robot").
StatusOr<std::string> HostIdentityFor(const Graph& graph, const std::string& host);

inline constexpr const char* kSubsetFile = "subset.yaml";

// What a keystore holds: everything (whole), or one machine's identities (subset.yaml).
struct KeystoreSubset {
  bool whole = true;
  std::string host;        // the host whose identities it holds; empty: none
  bool guest = false;      // it holds the guest identity
  std::string source;      // the whole keystore it was exported from (on the machine that did it)
  std::string graph_file;  // the graph file export was given
};
// The keystore's subset.yaml (whole when there is none); an unreadable or malformed one, or one
// that is a symbolic link, is an error naming the file.
StatusOr<KeystoreSubset> ReadKeystoreSubset(const std::string& keystore);
// The identities a subset of `graph`'s keystore holds (GraphIdentities for a whole one).
std::vector<std::string> SubsetIdentities(const Graph& graph, const KeystoreSubset& subset);
// OK when the graph is not secured or its keystore holds `identity`; else FailedPrecondition:
// "identity 'process.arm' is not in keystore K: it is the subset for host 'robot' (K/subset.yaml)
// ...; `dyad security export SOURCE --graph G --host lab OUT` on the machine with the whole
// keystore makes the one that holds it".
Status CheckIdentityHeld(const Graph& graph, const std::string& identity);

// The keystore's files for every identity of the graph (of its subset: SubsetIdentities) exist as regular files (not symbolic
// links), private keys are not readable by group or others, certificates are valid at
// `now_s` (Unix seconds). Returns the problems, each naming its file.
std::vector<std::string> CheckKeystore(const Graph& graph, int64_t now_s);

}  // namespace dyad
