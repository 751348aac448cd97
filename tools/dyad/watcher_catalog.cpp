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

}  // namespace

bool LoadWatcherCatalog(const std::string& graph_path, std::vector<std::string> plugins, Catalog* catalog,
                        IntrospectOptions* options, bool domain_given, const std::string& host, std::optional<Graph>* watched) {
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
      auto identity = HostIdentityFor(graph, host.empty() ? MachineName() : host);
      if (!identity.ok()) std::cerr << graph_path << ": " << identity.status().message() << "\n";
      if (!problems.empty() || !identity.ok()) return false;
      options->security = IdentityOf(graph, identity.value());
    }
  }
  if (Status s = catalog->LoadDefault(plugins); !s.ok()) std::cerr << "warning: " << s.message() << "\n";
  return true;
}


}  // namespace dyad::cli
