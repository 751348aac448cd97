#include "keystore_export.hpp"

#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <ostream>
#include <vector>

#include <yaml-cpp/yaml.h>

#include <dyad/keystore_graph.hpp>
#include <dyad/private_file.hpp>
#include <dyad/security.hpp>
#include <dyad/wire_names.hpp>

namespace dyad::cli {
namespace {

namespace fs = std::filesystem;

// The whole text of the regular file at `path`, never through a symbolic link.
StatusOr<std::string> ReadRegular(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return Status::IOError(path + ": cannot be read (" + WhatIsAt(path) + ": " + std::strerror(errno) + ")");
  struct stat st {};
  std::string text;
  bool ok = fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
  char buf[4096];
  ssize_t n = 0;
  while (ok && (n = ::read(fd, buf, sizeof buf)) > 0) text.append(buf, static_cast<size_t>(n));
  ::close(fd);
  if (!ok || n < 0) return Status::IOError(path + ": not a readable regular file (" + WhatIsAt(path) + ")");
  return text;
}

// The files of the subset, relative to the keystore: the CA certificates, the governance, the
// names key, the graph the keystore is for and each identity's four files.
std::vector<std::string> SubsetFiles(const std::string& keystore, const std::vector<std::string>& identities, bool web) {
  std::vector<std::string> files = {"identity_ca.cert.pem", "permissions_ca.cert.pem", "governance.xml", "governance.p7s"};
  files.insert(files.end(), {kNamesKeyFile, kKeystoreGraphFile});
  if (fs::exists(fs::symlink_status(fs::path(keystore) / "web_ca.cert.pem"))) files.push_back("web_ca.cert.pem");
  for (const std::string& id : identities)
    for (const char* f : {"cert.pem", "key.pem", "permissions.xml", "permissions.p7s"})
      files.push_back((fs::path("identities") / id / f).string());
  if (web)
    for (const char* f : {"web/tls.pem", "web/cert.pem", "web/hosts"}) files.push_back(f);
  return files;
}

std::string SubsetYaml(const Graph& graph, const ExportOptions& options, const std::vector<std::string>& identities) {
  YAML::Emitter e;
  e << YAML::Comment("dyad security export: the keystore of one machine of graph '" + graph.name +
                     "' (docs/security.md); it holds " + std::to_string(identities.size()) +
                     (identities.size() == 1 ? " identity" : " identities"));
  e << YAML::BeginMap;
  if (!options.host.empty()) e << YAML::Key << "host" << YAML::Value << options.host;
  if (options.guest) e << YAML::Key << "guest" << YAML::Value << true;
  e << YAML::Key << "graph" << YAML::Value << fs::absolute(graph.file).lexically_normal().string();
  e << YAML::Key << "from" << YAML::Value << fs::absolute(options.keystore).lexically_normal().string();
  e << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

// What the export may start from: a whole keystore of this graph, whose checks pass, and a new
// OUT with an existing parent; --host one of the graph's, --guest only with security.guests.
Status CheckExport(const Graph& graph, const ExportOptions& options) {
  if (options.host.empty() && !options.guest) return Status::InvalidArgument("give --host H, --guest, or both");
  const std::vector<std::string> hosts = IdentityHosts(graph);
  if (!options.host.empty() && std::find(hosts.begin(), hosts.end(), options.host) == hosts.end()) {
    std::string list;
    for (const std::string& h : hosts) list += (list.empty() ? "" : ", ") + h;
    return Status::InvalidArgument("--host " + options.host + ": not a host of graph '" + graph.name + "' (its hosts: " + list +
                                   ")");
  }
  if (options.guest && !graph.security.guests)
    return Status::InvalidArgument("--guest: graph '" + graph.name + "' has no security.guests, so no guest identity (add " +
                                   "`guests: {subscribe: [...], publish: [...]}` under security: (" +
                                   graph.security.mark.ToString() + ") and rerun `dyad security init`)");
  if (options.web && !fs::exists(fs::symlink_status(fs::path(options.keystore) / "web" / "tls.pem")))
    return Status::NotFound((fs::path(options.keystore) / "web" / "tls.pem").string() +
                            ": --web, and the keystore has no web certificate (make it with `dyad security init " +
                            options.keystore + " --graph " + graph.file + " --web-host HOST`)");
  auto subset = ReadKeystoreSubset(options.keystore);
  if (!subset.ok()) return subset.status();
  if (!subset.value().whole)
    return Status::FailedPrecondition(options.keystore + ": a subset itself (" + kSubsetFile +
                                      "): export from the whole keystore, on the machine that ran `dyad security init`");
  Graph source = graph;
  source.security.keystore = options.keystore;
  std::string problems;
  for (const std::string& p : CheckKeystore(source, static_cast<int64_t>(std::time(nullptr)))) problems += "\n  " + p;
  if (!problems.empty())
    return Status::FailedPrecondition(options.keystore + ": not a whole, valid keystore of graph '" + graph.name +
                                      "' (run `dyad security init` on it first):" + problems);
  if (fs::exists(fs::symlink_status(options.out)))
    return Status::FailedPrecondition(options.out + ": exists (" + WhatIsAt(options.out) +
                                      "): export makes a new folder, never over or into one");
  const fs::path parent = fs::absolute(options.out).parent_path();
  if (!fs::is_directory(parent)) return Status::NotFound(parent.string() + ": no such folder (OUT's parent must exist)");
  return Status::OK();
}

}  // namespace

Status ExportKeystore(const Graph& graph, const ExportOptions& options, std::ostream& out) {
  if (Status s = CheckExport(graph, options); !s.ok()) return s;
  KeystoreSubset subset;
  subset.whole = false;
  subset.host = options.host;
  subset.guest = options.guest;
  const std::vector<std::string> identities = SubsetIdentities(graph, subset);
  const fs::path target = fs::absolute(options.out).lexically_normal();
  std::string staging_name = target.filename().string();  // ".<OUT>.export-<pid>", beside OUT
  staging_name.insert(staging_name.begin(), '.');
  staging_name.append(".export-").append(std::to_string(getpid()));
  const fs::path staging = target.parent_path() / staging_name;
  std::error_code ec;
  const std::vector<std::string> files = SubsetFiles(options.keystore, identities, options.web);
  auto made = [&]() -> Status {
    for (const std::string& id : identities)
      if (Status s = CreatePrivateDirectories((staging / "identities" / id).string()); !s.ok()) return s;
    if (options.web)
      if (Status s = CreatePrivateDirectories((staging / "web").string()); !s.ok()) return s;
    for (const std::string& file : files) {
      auto text = ReadRegular((fs::path(options.keystore) / file).string());
      if (!text.ok()) return text.status();
      if (Status s = WritePrivateFile((staging / file).string(), text.value(), CreateMode::kNew); !s.ok()) return s;
    }
    return WritePrivateFile((staging / kSubsetFile).string(), SubsetYaml(graph, options, identities), CreateMode::kNew);
  }();
  if (made.ok() && ::renameat2(AT_FDCWD, staging.c_str(), AT_FDCWD, target.c_str(), RENAME_NOREPLACE) != 0)
    made = Status::IOError(target.string() + ": cannot put the subset in place: " + std::strerror(errno));
  if (!made.ok()) {
    fs::remove_all(staging, ec);
    return made;
  }
  if (Status s = SyncDirectory(target.parent_path().string()); !s.ok()) return s;
  for (const std::string& file : files) out << "copied   " << (target / file).string() << "\n";
  out << "wrote    " << (target / kSubsetFile).string() << "\n";
  return Status::OK();
}

}  // namespace dyad::cli
