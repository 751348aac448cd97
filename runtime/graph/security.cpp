#include <dyad/security.hpp>

#include <dyad/keystore_graph.hpp>
#include <dyad/wire_names.hpp>

#include <fnmatch.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>
#include <set>
#include <tuple>

#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/x509.h>
#include <yaml-cpp/yaml.h>

namespace dyad {
namespace {

namespace fs = std::filesystem;

std::string FileIn(const std::string& folder, const std::string& name) { return (fs::path(folder) / name).string(); }

// "" when `path` is a regular file that is not a symbolic link (and, for a key, not readable by
// group or others); else what is wrong.
std::string CheckFile(const std::string& path, bool secret) {
  struct stat st {};
  if (lstat(path.c_str(), &st) != 0) return path + ": missing";
  if (S_ISLNK(st.st_mode)) return path + ": a symbolic link (refused: it may point anywhere)";
  if (!S_ISREG(st.st_mode)) return path + ": not a regular file";
  if (secret && (st.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    return path + ": a private key readable by others (mode " + mode + "; chmod 600 it)";
  }
  return "";
}

// "" when the PEM certificate at `path` is valid at `now_s`; else why not.
std::string CheckCertificateDates(const std::string& path, int64_t now_s) {
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "r"), &std::fclose);
  if (!f) return path + ": cannot be read";
  std::unique_ptr<X509, void (*)(X509*)> cert(PEM_read_X509(f.get(), nullptr, nullptr, nullptr), &X509_free);
  if (!cert) return path + ": not a PEM certificate";
  time_t now = static_cast<time_t>(now_s);
  if (X509_cmp_time(X509_get0_notBefore(cert.get()), &now) > 0) return path + ": certificate not valid yet (check this machine's clock)";
  if (X509_cmp_time(X509_get0_notAfter(cert.get()), &now) < 0)
    return path + ": certificate expired (renew it: dyad security init --renew)";
  return "";
}

// "" when the private key at `key_path` is the key of the certificate at `cert_path`; else what
// is wrong. A renewal cut short between its two writes (by an older dyad, or by hand) leaves a
// pair whose files each pass every check and whose handshake fails: say so here instead.
std::string CheckKeyMatchesCertificate(const std::string& cert_path, const std::string& key_path) {
  std::unique_ptr<FILE, int (*)(FILE*)> cf(std::fopen(cert_path.c_str(), "r"), &std::fclose);
  std::unique_ptr<FILE, int (*)(FILE*)> kf(std::fopen(key_path.c_str(), "r"), &std::fclose);
  if (!cf || !kf) return "";  // CheckFile said it
  std::unique_ptr<X509, void (*)(X509*)> cert(PEM_read_X509(cf.get(), nullptr, nullptr, nullptr), &X509_free);
  std::unique_ptr<EVP_PKEY, void (*)(EVP_PKEY*)> key(PEM_read_PrivateKey(kf.get(), nullptr, nullptr, nullptr), &EVP_PKEY_free);
  ERR_clear_error();
  if (!cert) return "";  // CheckCertificateDates said it
  if (!key) return key_path + ": not a PEM private key";
  const bool match = X509_check_private_key(cert.get(), key.get()) == 1;
  ERR_clear_error();
  if (match) return "";
  return key_path + ": not the key of " + cert_path + " (renew the pair: dyad security init --renew)";
}

// Whom the subset is for, for messages: "host 'robot'", "the guest", "host 'lab' and the guest".
std::string SubsetFor(const KeystoreSubset& s) {
  const std::string host = s.host.empty() ? "" : "host '" + s.host + "'";
  if (!s.guest) return host;
  return host.empty() ? "the guest" : host + " and the guest";
}

// The export option that gives `identity`: "--host lab" or "--guest".
std::string ExportOptionFor(const Graph& graph, const std::string& identity) {
  if (identity == kGuestIdentity) return "--guest";
  const std::string host = "host.", process = "process.";
  if (identity.rfind(host, 0) == 0) return "--host " + identity.substr(host.size());
  const std::string name = identity.substr(identity.rfind(process, 0) == 0 ? process.size() : 0);
  if (const ProcessConfig* p = graph.FindProcess(name); p != nullptr && !p->host.empty()) return "--host " + p->host;
  return "--host " + IdentityHosts(graph).front();  // a process on no host runs on every one
}

}  // namespace

StatusOr<KeystoreSubset> ReadKeystoreSubset(const std::string& keystore) {
  KeystoreSubset subset;
  const std::string path = FileIn(keystore, kSubsetFile);
  struct stat st {};
  if (lstat(path.c_str(), &st) != 0) return subset;
  if (std::string problem = CheckFile(path, false); !problem.empty()) return Status::InvalidArgument(problem);
  const std::string made = " (made by `dyad security export`: export again, or remove it from a whole keystore)";
  try {
    const YAML::Node doc = YAML::LoadFile(path);
    if (!doc.IsMap()) return Status::InvalidArgument(path + ": not a map of host, guest, graph and from" + made);
    for (const auto& kv : doc) {
      const std::string key = kv.first.as<std::string>();
      if (key == "host") subset.host = kv.second.as<std::string>();
      else if (key == "guest") subset.guest = kv.second.as<bool>();
      else if (key == "graph") subset.graph_file = kv.second.as<std::string>();
      else if (key == "from") subset.source = kv.second.as<std::string>();
      else return Status::InvalidArgument(path + ": unknown key '" + key + "' (host, guest, graph, from)" + made);
    }
  } catch (const YAML::Exception& e) {
    return Status::InvalidArgument(path + ": " + e.what() + made);
  }
  if (subset.host.empty() && !subset.guest) return Status::InvalidArgument(path + ": says neither a host nor guest: true" + made);
  subset.whole = false;
  return subset;
}

std::vector<std::string> SubsetIdentities(const Graph& graph, const KeystoreSubset& subset) {
  if (subset.whole) return GraphIdentities(graph);
  std::vector<std::string> out;
  if (!subset.host.empty()) {
    for (const std::string& p : graph.ProcessNames()) {  // sorted
      const ProcessConfig* config = graph.FindProcess(p);
      const std::string where = config == nullptr ? "" : config->host;
      if (where == subset.host || where.empty()) out.push_back(ProcessIdentity(p));
    }
    out.push_back(HostIdentity(subset.host));
  }
  if (subset.guest) out.push_back(kGuestIdentity);
  return out;
}

Status CheckIdentityHeld(const Graph& graph, const std::string& identity) {
  if (!graph.security.enabled()) return Status::OK();
  auto subset = ReadKeystoreSubset(graph.security.keystore);
  if (!subset.ok()) return subset.status();
  const std::vector<std::string> held = SubsetIdentities(graph, subset.value());
  if (std::find(held.begin(), held.end(), identity) != held.end()) return Status::OK();
  std::string list;
  for (const std::string& h : held) list += (list.empty() ? "" : ", ") + h;
  const KeystoreSubset& s = subset.value();
  return Status::FailedPrecondition(
      "identity '" + identity + "' is not in keystore " + graph.security.keystore + ": it is the subset for " + SubsetFor(s) +
      " (" + FileIn(graph.security.keystore, kSubsetFile) + "), which holds only " + list +
      "; on the machine with the whole keystore, `dyad security export " + (s.source.empty() ? "KEYSTORE" : s.source) +
      " --graph " + (s.graph_file.empty() ? graph.file : s.graph_file) + " " + ExportOptionFor(graph, identity) +
      " OUT` makes the subset that holds it (copy OUT here as the keystore)");
}

std::string ProcessIdentity(const std::string& process) { return "process." + process; }
std::string HostIdentity(const std::string& host) { return "host." + host; }

std::vector<std::string> IdentityHosts(const Graph& graph) {
  std::set<std::string> hosts;
  for (const auto& p : graph.processes)
    if (!p.host.empty()) hosts.insert(p.host);
  for (const auto& [host, address] : graph.network.hosts) hosts.insert(host);
  if (hosts.empty()) hosts.insert(kLocalHost);
  return {hosts.begin(), hosts.end()};
}

std::vector<std::string> GraphIdentities(const Graph& graph) {
  std::vector<std::string> out;
  for (const std::string& p : graph.ProcessNames()) out.push_back(ProcessIdentity(p));
  for (const std::string& h : IdentityHosts(graph)) out.push_back(HostIdentity(h));
  if (graph.security.guests) out.push_back(kGuestIdentity);
  return out;
}

bool TopicGranted(const std::vector<std::string>& grants, const std::string& topic) {
  for (const std::string& g : grants)
    if (fnmatch(g.c_str(), topic.c_str(), 0) == 0) return true;
  return false;
}

std::string IdentitySubject(const Graph& graph, const std::string& identity) {
  if (identity == kGuestIdentity) return "CN=dyad/" + graph.name + "/guest/tools";
  const std::string host = "host.", process = "process.";
  if (identity.rfind(host, 0) == 0) return "CN=dyad/" + graph.name + "/host/" + identity.substr(host.size());
  return "CN=dyad/" + graph.name + "/" + identity.substr(identity.rfind(process, 0) == 0 ? process.size() : 0);
}

IdentityFiles IdentityOf(const Graph& graph, const std::string& identity) {
  IdentityFiles f;
  if (!graph.security.enabled()) return f;
  const std::string& k = graph.security.keystore;
  const std::string own = FileIn(FileIn(k, "identities"), identity);
  f.identity_ca = FileIn(k, "identity_ca.cert.pem");
  f.permissions_ca = FileIn(k, "permissions_ca.cert.pem");
  f.governance = FileIn(k, "governance.p7s");
  f.certificate = FileIn(own, "cert.pem");
  f.private_key = FileIn(own, "key.pem");
  f.permissions = FileIn(own, "permissions.p7s");
  return f;
}

StatusOr<std::string> HostIdentityFor(const Graph& graph, const std::string& host) {
  const std::vector<std::string> hosts = IdentityHosts(graph);
  for (const std::string& h : hosts)
    if (h == host) return HostIdentity(h);
  if (hosts.size() == 1) return HostIdentity(hosts.front());
  std::string flags;  // "--host a, --host b or --host c"
  for (size_t i = 0; i < hosts.size(); ++i)
    flags += (i == 0 ? "" : i + 1 == hosts.size() ? " or " : ", ") + std::string("--host ") + hosts[i];
  return Status::NotFound("this machine ('" + host + "') is none of the graph's hosts: pass the host it is, or whose " +
                          "identity it may use here: " + flags);
}

std::vector<std::string> CheckKeystore(const Graph& graph, int64_t now_s) {
  std::vector<std::string> problems;
  if (!graph.security.enabled()) return problems;
  if (!fs::is_directory(graph.security.keystore)) {
    problems.push_back(graph.security.keystore + ": no such folder (make it with `dyad security init " +
                       graph.security.keystore + " --graph " + graph.file + "`)");
    return problems;
  }
  // Every participant's name on the wire is made with it (dyad/wire_names.hpp).
  if (std::string problem = CheckFile(FileIn(graph.security.keystore, kNamesKeyFile), true); !problem.empty())
    problems.push_back(problem + " (the keystore's names key: make it with `dyad security init " + graph.security.keystore +
                       " --graph " + graph.file + "`)");
  // One graph per keystore (dyad/keystore_graph.hpp).
  if (auto owner = ReadKeystoreGraph(graph.security.keystore); !owner.ok()) {
    problems.push_back(owner.status().message());
  } else if (owner.value().empty()) {
    problems.push_back(FileIn(graph.security.keystore, kKeystoreGraphFile) +
                       ": missing (the graph this keystore is for; one made before dyad recorded it: run `dyad security init " +
                       graph.security.keystore + " --graph " + graph.file +
                       "` on the whole keystore, then export again for each machine)");
  } else if (Status s = CheckKeystoreGraph(graph, graph.security.keystore); !s.ok()) {
    problems.push_back(s.message());
  }
  auto subset = ReadKeystoreSubset(graph.security.keystore);
  if (!subset.ok()) {
    problems.push_back(subset.status().message());
    return problems;
  }
  if (!subset.value().whole) {
    const std::vector<std::string> hosts = IdentityHosts(graph);
    const std::string file = FileIn(graph.security.keystore, kSubsetFile);
    if (!subset.value().host.empty() && std::find(hosts.begin(), hosts.end(), subset.value().host) == hosts.end())
      problems.push_back(file + ": the subset for host '" + subset.value().host + "', which is none of graph '" + graph.name +
                         "''s hosts (export the subset of this machine's host from the whole keystore)");
    if (subset.value().guest && !graph.security.guests)
      problems.push_back(file + ": the guest's subset, and the graph has no security.guests");
    if (!problems.empty()) return problems;
  }
  std::set<std::string> checked;
  for (const std::string& identity : SubsetIdentities(graph, subset.value())) {
    const IdentityFiles f = IdentityOf(graph, identity);
    for (const auto& [path, secret, certificate] : {std::tuple{f.identity_ca, false, true}, {f.permissions_ca, false, true},
                                                    {f.governance, false, false}, {f.certificate, false, true},
                                                    {f.private_key, true, false}, {f.permissions, false, false}}) {
      if (!checked.insert(path).second) continue;
      std::string problem = CheckFile(path, secret);
      if (problem.empty() && certificate) problem = CheckCertificateDates(path, now_s);
      if (!problem.empty()) problems.push_back("identity '" + identity + "': " + problem);
    }
    if (CheckFile(f.certificate, false).empty() && CheckFile(f.private_key, true).empty())
      if (std::string problem = CheckKeyMatchesCertificate(f.certificate, f.private_key); !problem.empty())
        problems.push_back("identity '" + identity + "': " + problem);
  }
  return problems;
}

}  // namespace dyad
