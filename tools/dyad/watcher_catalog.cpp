#include "watcher_catalog.hpp"

#include <unistd.h>

#include <ctime>
#include <iostream>

#include <dyad/security.hpp>

namespace dyad::cli {

namespace {

std::string MachineName() {
  char name[256] = {0};
  gethostname(name, sizeof(name) - 1);
  return name;
}

// The identity a visitor of the secured `graph` joins with: its host's; on a machine that is none
// of the graph's hosts (no --host), the guest's for a tool that may be one (`as_guest`).
// A keystore subset made for host H (dyad security export) says this machine is H unless --host
// says otherwise.
StatusOr<std::string> JoiningIdentity(const Graph& graph, const std::string& graph_path, const std::string& given_host,
                                      bool* as_guest) {
  std::string host = given_host;
  if (auto subset = ReadKeystoreSubset(graph.security.keystore); host.empty() && subset.ok()) host = subset.value().host;
  const std::string machine = host.empty() ? MachineName() : host;
  auto identity = HostIdentityFor(graph, machine);
  if (identity.ok() || !host.empty()) return identity;
  if (as_guest == nullptr && graph.security.guests)  // status, topics, param, graph --live
    return Status::NotFound(identity.status().message() +
                            " (not as the graph's guest: this tool reads the runtime's own topics, which only a host's "
                            "identity may read)");
  if (as_guest == nullptr) return identity;
  if (!graph.security.guests)
    return Status::NotFound(identity.status().message() +
                            ", or let tools visit it as the graph's guest: add `guests: {subscribe: [...], "
                            "publish: [...]}` under security: (" +
                            graph.security.mark.ToString() + "), then rerun `dyad security init " + graph.security.keystore +
                            " --graph " + graph_path + "`");
  std::cerr << "note: this machine ('" << machine << "') is none of the hosts of graph '" << graph.name
            << "': joining as its guest (security.guests; --host H to join as host H)\n";
  *as_guest = true;
  return std::string(kGuestIdentity);
}

}  // namespace

bool GuestMayRead(const Graph& graph, const std::string& graph_path, const std::vector<std::string>& topics,
                  const std::string& tool) {
  const SecurityConfig& sec = graph.security;
  const std::string where = sec.guest_publish.empty() ? "security.guests, " + sec.guests_mark.ToString()
                                                      : "beside security.guests.publish, " + sec.guests_mark.ToString();
  bool ok = true;
  for (const std::string& t : topics)
    if (!TopicGranted(sec.guest_subscribe, t)) {
      std::cerr << tool << ": topic '" << t << "': the graph's guests may not read it: add it to security.guests.subscribe ("
                << where << "), then rerun `dyad security init " << sec.keystore << " --graph " << graph_path << "`\n";
      ok = false;
    }
  return ok;
}

bool LoadWatcherCatalog(const std::string& graph_path, std::vector<std::string> plugins, Catalog* catalog,
                        IntrospectOptions* options, bool domain_given, const std::string& host, std::optional<Graph>* watched,
                        bool* as_guest) {
  if (!graph_path.empty()) {
    std::vector<Diagnostic> diagnostics;
    const Graph graph = LoadGraph(graph_path, {}, &diagnostics);
    for (const Diagnostic& d : diagnostics) std::cerr << d.ToString() << "\n";
    if (!diagnostics.empty()) return false;
    if (graph.clock == ClockMode::kStepped)
      std::cerr << "warning: " << graph_path << ": clock: stepped: a stepped run keeps its DDS inside its process; watchers see "
                   "only a run with --set clock=wall\n";
    if (watched != nullptr) *watched = graph;
    plugins.insert(plugins.end(), graph.plugins.begin(), graph.plugins.end());
    if (options != nullptr) {
      options->network = graph.network;
      options->graph_name = graph.name;
      if (!domain_given) options->domain_id = graph.domain_id;
    }
    if (options != nullptr && graph.security.enabled()) {
      const std::vector<std::string> problems = CheckKeystore(graph, static_cast<int64_t>(std::time(nullptr)));
      for (const std::string& p : problems) std::cerr << graph.security.mark.ToString() << ": security.keystore: " << p << "\n";
      if (!problems.empty()) return false;
      auto identity = JoiningIdentity(graph, graph_path, host, as_guest);
      if (!identity.ok()) std::cerr << graph_path << ": " << identity.status().message() << "\n";
      if (!identity.ok()) return false;
      if (Status s = CheckIdentityHeld(graph, identity.value()); !s.ok()) {
        std::cerr << graph_path << ": " << s.message() << "\n";
        return false;
      }
      options->security = IdentityOf(graph, identity.value());
    }
  }
  if (Status s = catalog->LoadDefault(plugins); !s.ok()) std::cerr << "warning: " << s.message() << "\n";
  return true;
}

}  // namespace dyad::cli
