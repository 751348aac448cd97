#include "security_commands.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>
#include <memory>

#include <dyad/catalog.hpp>
#include <dyad/graph.hpp>
#include <dyad/security.hpp>
#include <dyad/validate.hpp>

#include "exit_code.hpp"
#include "keystore.hpp"
#include "keystore_export.hpp"

namespace dyad::cli {

using enum tools::ExitCode;
namespace {

// The graph, validated as `dyad validate` does (plugins included: permissions come from what
// each component's Configure reads and writes), except for its own `security:` keystore,
// which is what this command makes. Returns 2 having printed the problems, else 0.
int LoadForKeystore(const std::string& path, const std::vector<std::string>& sets, const std::vector<std::string>& plugins,
                    Graph* graph, std::map<std::string, TopicAccess>* access) {
  std::vector<Diagnostic> diags;
  std::vector<Override> overrides;
  for (const std::string& s : sets) overrides.push_back(Override{s});
  *graph = LoadGraph(path, overrides, &diags);
  Catalog catalog;
  for (size_t i = 0; i < graph->plugins.size(); ++i)
    if (Status s = catalog.Load(graph->plugins[i]); !s.ok()) diags.push_back({graph->plugin_marks[i], "plugins", s.message()});
  if (Status s = catalog.LoadDefault(plugins); !s.ok()) std::cerr << "warning: " << s.message() << "\n";
  if (diags.empty()) {
    const ResolvedGraph resolved = ValidateGraph(*graph, catalog, &diags);
    std::vector<Diagnostic> kept;
    for (auto& d : diags)
      if (d.key.rfind("security", 0) != 0) kept.push_back(std::move(d));
    diags = std::move(kept);
    if (diags.empty()) *access = TopicAccessByProcess(*graph, resolved, catalog, &diags);
  }
  for (const auto& d : diags) std::cerr << d.ToString() << "\n";
  if (diags.empty()) return tools::Code(kOk);
  std::cerr << path << ": " << diags.size() << " problem" << (diags.size() == 1 ? "" : "s") << ", no keystore was made\n";
  return tools::Code(kBadInput);
}

// `dyad security export KEYSTORE --graph G (--host H | --guest) OUT` (keystore_export.hpp).
void AddExportCommand(CLI::App& security, int& exit_code) {
  struct State {
    ExportOptions options;
    std::string graph;
    std::vector<std::string> sets;
  };
  auto st = std::make_shared<State>();
  auto* cmd = security.add_subcommand(
      "export",
      "Write OUT, the part of KEYSTORE one machine needs: CA certificates (no CA key), governance, names.key "
      "and only its identities (--host H: H's launcher and watchers and the processes on H; --guest: the guest's)");
  cmd->add_option("keystore", st->options.keystore, "The whole keystore (dyad security init's)")->required();
  cmd->add_option("out", st->options.out, "The new folder to write (must not exist); copy it to the machine as its keystore")
      ->required();
  cmd->add_option("--graph", st->graph, "The graph")->required();
  cmd->add_option("--host", st->options.host, "The host whose identities to export");
  cmd->add_flag("--guest", st->options.guest, "The guest identity (security.guests), for a machine that is none of the hosts");
  cmd->add_flag("--web", st->options.web,
                "Also the web component's TLS key and certificate (web/, from init --web-host), for the machine that runs it");
  cmd->add_option("--set", st->sets, "Change a key of the graph, as `dyad run --set` does");
  cmd->callback([st, &exit_code] {
    std::vector<Diagnostic> diags;
    std::vector<Override> overrides;
    for (const std::string& s : st->sets) overrides.push_back(Override{s});
    const Graph graph = LoadGraph(st->graph, overrides, &diags);
    for (const auto& d : diags) std::cerr << d.ToString() << "\n";
    if (!diags.empty()) {
      exit_code = tools::Code(kBadInput);
      return;
    }
    if (Status s = ExportKeystore(graph, st->options, std::cout); !s.ok()) {
      std::cerr << "dyad security export: " << s.message() << "\n";
      exit_code = tools::Code(kBadInput);
      return;
    }
    std::cout << "subset " << st->options.out << ": copy it to the machine and name it in the graph's security.keystore there\n";
    exit_code = tools::Code(kOk);
  });
}

}  // namespace

void AddSecurityCommands(CLI::App& app, int& exit_code) {
  struct State {
    KeystoreOptions keystore;
    std::string graph;
    std::vector<std::string> plugins, renew, sets;
  };
  auto st = std::make_shared<State>();
  auto* security = app.add_subcommand("security", "DDS Security for a graph: its keystore (docs/security.md)");
  security->require_subcommand(1);
  auto* init = security->add_subcommand(
      "init", "Make or update DIR, the keystore of --graph: CAs, one identity per process and per host, governance, "
              "permissions from what each process reads and writes; existing keys are kept");
  init->add_option("dir", st->keystore.dir, "The keystore folder (the graph's security.keystore)")->required();
  init->add_option("--graph", st->graph, "The graph")->required();
  init->add_option("--ca", st->keystore.ca_dir,
                   "The folder of the CA keys (default DIR/ca): where an offline CA is brought back from, e.g. a USB key");
  init->add_option("--plugins", st->plugins, "Extra plugin file or folder (repeatable)");
  init->add_option("--set", st->sets, "Change a key of the graph, as `dyad run --set` does (the runs must use the same sets)");
  init->add_option("--renew", st->renew, "Replace the key and certificate of this identity (process.NAME, host.NAME, web, or all; repeatable)");
  init->add_option("--days", st->keystore.identity_days, "Validity of newly issued identities, days (default 365)")->check(CLI::Range(1, 36500));
  init->add_option("--web-host", st->keystore.web_hosts,
                   "Also make the web CA and web/tls.pem, a TLS certificate for the web component (params.tls_certificate) "
                   "valid for this DNS name or address (repeatable)");
  init->add_option("--ca-days", st->keystore.ca_days, "Validity of new CAs, days (default 3650)")->check(CLI::Range(1, 36500));
  init->callback([st, &exit_code] {
    if (auto subset = ReadKeystoreSubset(st->keystore.dir); subset.ok() && !subset.value().whole) {
      std::cerr << "dyad security init: " << st->keystore.dir << " is a subset (" << kSubsetFile
                << ", made by `dyad security export`): init works on the whole keystore; run it there, then export again\n";
      exit_code = tools::Code(kBadInput);
      return;
    }
    Graph graph;
    std::map<std::string, TopicAccess> access;
    if ((exit_code = LoadForKeystore(st->graph, st->sets, st->plugins, &graph, &access)) != 0) return;
    const std::vector<std::string> identities = GraphIdentities(graph);
    for (const std::string& r : st->renew)
      if (r != "all" && r != "web" && std::find(identities.begin(), identities.end(), r) == identities.end()) {
        std::cerr << "dyad security init: --renew " << r << ": not an identity of graph '" << graph.name << "' (";
        for (size_t i = 0; i < identities.size(); ++i) std::cerr << (i ? ", " : "") << identities[i];
        std::cerr << ")\n";
        exit_code = tools::Code(kBadInput);
        return;
      }
    st->keystore.renew = {st->renew.begin(), st->renew.end()};
    if (Status s = InitKeystore(graph, access, st->keystore, std::cout); !s.ok()) {
      std::cerr << "dyad security init: " << s.message() << "\n";
      exit_code = tools::Code(kFailure);
      return;
    }
    std::cout << "keystore " << st->keystore.dir << ": " << identities.size()
              << " identities; the graph uses it with `security: {keystore: " << st->keystore.dir << "}`\n";
    exit_code = tools::Code(kOk);
  });
  AddExportCommand(*security, exit_code);
}

}  // namespace dyad::cli
