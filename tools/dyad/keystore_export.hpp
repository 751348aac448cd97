// `dyad security export KEYSTORE --graph G (--host H | --guest) OUT`: the keystore subset one
// machine of the graph holds (dyad/security.hpp), so that no machine holds another's keys.
//
// Contract:
//   - KEYSTORE is a whole keystore (`dyad security init`'s, no subset.yaml) that passes
//     CheckKeystore for the graph; anything else is refused, naming what is wrong.
//   - OUT must not exist (nothing is ever written over or into an existing folder); its parent
//     must. The subset is made in a staging folder beside OUT and renamed to OUT in one step, so a
//     failure leaves no OUT. Folders 0700, files 0600 (O_EXCL | O_NOFOLLOW, dyad/private_file.hpp).
//   - OUT holds the CA certificates (identity_ca.cert.pem, permissions_ca.cert.pem, and
//     web_ca.cert.pem when there is one), never a CA key; governance.xml and .p7s; names.key;
//     graph.name (the graph the keystore is for: dyad/keystore_graph.hpp);
//     identities/<identity>/ for exactly SubsetIdentities (host H: host.H and the processes placed
//     on H or on no host; guest: guest; both when both are asked); and subset.yaml, which says
//     whom it is for, the graph file and the keystore it came from (absolute paths: what a refusal
//     on that machine names in the export command that would help).
//   - With `web`: also web/tls.pem, web/cert.pem and web/hosts (the web component's TLS key and
//     certificate, `dyad security init --web-host`), for the machine that runs the web component;
//     without it an export holds no web/ (refused when the keystore has no web/tls.pem).
//   - --host H must be one of the graph's identity hosts; --guest needs security.guests (refused
//     naming the key otherwise).
// Each written file is reported on `out`.
#pragma once

#include <iosfwd>
#include <string>

#include <dyad/graph.hpp>
#include <dyad/status.hpp>

namespace dyad::cli {

struct ExportOptions {
  std::string keystore;  // the whole keystore
  std::string out;       // the new folder
  std::string host;      // the host whose identities to export; empty: none
  bool guest = false;    // the guest identity too
  bool web = false;      // the web component's TLS key and certificate (web/) too
};

Status ExportKeystore(const Graph& graph, const ExportOptions& options, std::ostream& out);

}  // namespace dyad::cli
