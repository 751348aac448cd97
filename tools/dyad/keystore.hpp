// `dyad security init`: the keystore of a graph (layout: dyad/security.hpp), made with OpenSSL's
// library the way sros2 makes a ROS 2 keystore.
//
// Contract:
//   - Two CAs (identity, permissions): self-signed ECDSA P-256, valid `ca_days`. Made once; their
//     keys stay in the CA folder, `ca_dir` (default DIR/ca/; move it off the experiment machines
//     after issuing: a run needs only the certificates; `init` needs the keys again only to issue
//     or sign something, and then names the key file it looked for). The CA folder is created
//     only when a CA is made: an init that has nothing to issue never makes an empty one.
//   - One identity per process and per host (GraphIdentities): an ECDSA P-256 key and a
//     certificate issued by the identity CA for `identity_days`, subject IdentitySubject. An
//     identity is issued or renewed as one step: key, certificate and permissions are made in a
//     staging folder that then replaces DIR/identities/<identity> atomically, so a failure or
//     crash leaves the identity as it was (never an empty folder, never a key beside another
//     key's certificate).
//   - governance.p7s and every permissions.p7s: the XML of access_documents.hpp, S/MIME-signed
//     by the permissions CA (openssl smime -sign -text, as Fast DDS verifies it).
//   - A rerun is safe: existing keys and certificates are kept (an identity the graph gained is
//     issued: that is how a new host or process is admitted), documents are re-signed only when
//     their text changed. `renew` names identities whose key and certificate are replaced
//     (rotation); "all" renews every identity. CA keys are never replaced.
//   - With `web_hosts` (names or addresses the browsers use): a third CA, the web CA (made once,
//     web_ca.cert.pem: what the browsers trust), and web/tls.pem, the web component's
//     `tls_certificate`: a new ECDSA P-256 key and a TLS server certificate for exactly those
//     hosts (subjectAltName), valid `identity_days`; web/cert.pem is the certificate alone. It is
//     reissued when the hosts change or with `renew` "web" (or "all").
//   - One graph per keystore (dyad/keystore_graph.hpp): DIR/graph.name records the graph it is
//     for (written when missing); an init for another graph is refused before anything is made
//     or renewed, naming the keystore's graph, its record and the fix (a keystore per graph).
//   - Folders 0700, files 0600, created O_EXCL | O_NOFOLLOW (dyad/private_file.hpp).
// Each created or kept file is reported on `out`; errors name the file.
#pragma once

#include <iosfwd>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <dyad/graph.hpp>
#include <dyad/status.hpp>
#include <dyad/validate.hpp>

namespace dyad::cli {

struct KeystoreOptions {
  std::string dir;
  std::string ca_dir;  // the CA keys' folder; empty: DIR/ca
  int ca_days = 3650;
  int identity_days = 365;
  std::set<std::string> renew;  // identities to reissue; {"all"}: every one
  std::vector<std::string> web_hosts;  // DNS names or IP addresses of the web component's TLS certificate
};

Status InitKeystore(const Graph& graph, const std::map<std::string, TopicAccess>& access, const KeystoreOptions& options,
                    std::ostream& out);

}  // namespace dyad::cli
