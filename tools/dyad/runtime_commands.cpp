#include "runtime_commands.hpp"

#include <errno.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <iomanip>
#include <sstream>
#include <iostream>
#include <memory>

#include <dyad/catalog.hpp>
#include <dyad/discovery_server.hpp>
#include <dyad/introspect.hpp>
#include <dyad/run.hpp>

#include <dyad/validate.hpp>

#include "exit_code.hpp"
#include "graph_dot.hpp"
#include "reference_markdown.hpp"
#include "run_process.hpp"
#include "watcher_catalog.hpp"

namespace dyad::cli {

using enum tools::ExitCode;
namespace {

// `--set` of validate and run (docs/runtime.md, "Composing graphs").
const char* const kSetHelp =
    "Change a key of the graph: COMPONENT.PARAM=VALUE, COMPONENT.type=TYPE (rate_hz, trigger, process, inputs.PORT, "
    "outputs.PORT), clock|seed|domain_id|graph=VALUE, network.KEY=VALUE, processes.NAME.KEY=VALUE (repeatable)";

std::vector<Override> ToOverrides(const std::vector<std::string>& sets) {
  std::vector<Override> out;
  for (const auto& s : sets) out.push_back(Override{s});
  return out;
}

void PrintType(const std::string& name, const CatalogEntry& e, std::ostream& out) {
  out << name << "  (" << e.type.plugin_path << ")\n";
  if (!e.spec.summary().empty()) out << "  " << e.spec.summary() << "\n";
  for (const auto& p : e.spec.inputs())
    out << "  input  " << p.name << ": " << p.type->short_name() << (p.optional ? " (optional)" : "")
        << (p.doc.empty() ? "" : "  # " + p.doc) << "\n";
  for (const auto& p : e.spec.outputs())
    out << "  output " << p.name << ": " << p.type->short_name() << (p.doc.empty() ? "" : "  # " + p.doc) << "\n";
  for (const auto& p : e.spec.params()) {
    out << "  param  " << p.name << ": " << ToString(p.type) << (p.path ? " path" : "") << (p.live ? " live" : "");
    out << (p.default_value ? " = " + ToYamlText(*p.default_value) : " (required)");
    if (!p.unit.empty()) out << " [" << p.unit << "]";
    if (p.min || p.max) out << " range " << ParamRangeText(p);
    if (!p.choices.empty()) {
      out << " one of";
      for (const auto& c : p.choices) out << " " << c;
    }
    if (!p.doc.empty()) out << "  # " << p.doc;
    out << "\n";
  }
}

// The DOT text on stdout, or rendered into `svg` by Graphviz's dot.
int EmitDot(const std::string& dot, const std::string& svg) {
  if (svg.empty()) {
    std::cout << dot;
    return tools::Code(kOk);
  }
  const std::string dot_file = svg + ".dot";
  std::ofstream(dot_file) << dot;
  const tools::ExitStatus rc = tools::RunProcess({"dot", "-Tsvg", "-o", svg, dot_file});
  if (rc.never_started() && rc.error() == ENOENT) {
    std::cerr << "dyad graph --svg: Graphviz's dot is not on PATH (Debian: apt install graphviz); the DOT text is in " << dot_file << "\n";
    return tools::Code(kFailure);
  }
  if (!rc.ok()) {
    std::cerr << "dyad graph --svg: dot -Tsvg " << dot_file << " failed (" << rc.ToString() << ")\n";
    return tools::Code(kFailure);
  }
  std::filesystem::remove(dot_file);
  std::cout << "wrote " << svg << "\n";
  return tools::Code(kOk);
}

// `dyad graph`: the graph checked against the component types (not configured: a picture needs
// no model file), as DOT on stdout or rendered by Graphviz's dot into an SVG.
int DrawGraph(const std::string& path, const std::vector<std::string>& sets, const std::vector<std::string>& plugins,
              const std::string& svg) {
  std::vector<Diagnostic> diags;
  const Graph graph = LoadGraph(path, ToOverrides(sets), &diags);
  Catalog catalog;
  for (size_t i = 0; i < graph.plugins.size(); ++i)
    if (Status s = catalog.Load(graph.plugins[i]); !s.ok()) diags.push_back({graph.plugin_marks[i], "plugins", s.message()});
  for (const auto& p : plugins)
    if (Status s = catalog.Load(p); !s.ok()) diags.push_back({SourceMark{"--plugins " + p, 0, 0}, "", s.message()});
  if (Status s = catalog.LoadDefault({}); !s.ok()) std::cerr << "warning: " << s.message() << "\n";
  ResolvedGraph resolved;
  if (diags.empty()) resolved = ValidateGraph(graph, catalog, &diags);
  for (const auto& d : diags) std::cerr << d.ToString() << "\n";
  if (!diags.empty()) {
    std::cerr << path << ": " << diags.size() << " problem" << (diags.size() == 1 ? "" : "s") << ", nothing was drawn\n";
    return tools::Code(kBadInput);
  }
  return EmitDot(GraphDot(graph, resolved), svg);
}

// `dyad graph --live`: the graphs on the domain as discovered, with measured rates.
int DrawLiveGraph(const std::string& path, IntrospectOptions options, bool domain_given, double listen_s, const std::string& svg,
                  const std::string& host) {
  Catalog catalog;
  std::optional<Graph> graph;
  if (!LoadWatcherCatalog(path, {}, &catalog, &options, domain_given, host, &graph)) return tools::Code(kBadInput);
  LiveGraph live;
  if (int rc = DiscoverLiveGraph(options, catalog, graph ? &*graph : nullptr, listen_s, &live, std::cerr); rc != 0) return rc;
  return EmitDot(LiveGraphDot(live, graph ? &*graph : nullptr), svg);
}

// `dyad graph`: the graph file's picture, or (--live) the running graph's.
void AddGraphCommand(CLI::App& app, int& exit_code) {
  struct State {
    std::string graph_path, svg, host;
    std::vector<std::string> sets, plugins;
    bool dot = false, live = false;
    IntrospectOptions watch;
    double listen_s = 2;
  };
  auto st = std::make_shared<State>();
  auto* graph = app.add_subcommand("graph", "Draw a graph: components, topics, processes and hosts (Graphviz DOT, or SVG)");
  graph->add_option("graph", st->graph_path, "Graph YAML file (with --live: optional, its domain and processes)");
  graph->add_flag("--live", st->live, "The running graph as discovered on the domain, with each topic's measured rate");
  auto* domain = graph->add_option("--domain", st->watch.domain_id, "--live: DDS domain id (default: the graph's, else 0)")->check(CLI::Range(0, 232));
  graph->add_option("--wait", st->watch.wait_s, "--live: seconds of discovery at most (default 5; with a graph it ends once all is found)")
      ->check(CLI::NonNegativeNumber);
  graph->add_option("--listen", st->listen_s, "--live: seconds to measure the rates (default 2)")->check(CLI::PositiveNumber);
  graph->add_option(
      "--host", st->host,
      "--live, with a secured graph: this machine's host in the graph, whose identity it uses (default: the machine's name)");
  graph->add_option("--set", st->sets, kSetHelp);
  graph->add_option("--plugins", st->plugins, "Extra plugin file or folder (repeatable)");
  auto* svg = graph->add_option("--svg", st->svg, "Render into this SVG file with Graphviz's dot (Debian: graphviz)");
  graph->add_flag("--dot", st->dot, "Print the DOT text (the default)")->excludes(svg);
  graph->callback([st, domain, &exit_code] {
    if (st->live) {
      exit_code = DrawLiveGraph(st->graph_path, st->watch, domain->count() > 0, st->listen_s, st->svg, st->host);
    } else if (st->graph_path.empty()) {
      std::cerr << "dyad graph: name the graph file (or --live for the running graph as discovered)\n";
      exit_code = tools::Code(kBadInput);
    } else {
      exit_code = DrawGraph(st->graph_path, st->sets, st->plugins, st->svg);
    }
  });
}

}  // namespace

void AddRuntimeCommands(CLI::App& app, int& exit_code) {
  // Owned by this registration (one per CLI::App), shared by its subcommands: a second App in
  // the same process (tests, embedding programs) starts from the defaults again.
  struct State {
    RunOptions run;
    std::vector<std::string> sets, plugins, type_names;
    bool markdown = false, messages = false, no_plugins = false;
    std::string listen;  // discovery-server --listen
  };
  auto st = std::make_shared<State>();
  RunOptions& run = st->run;
  std::vector<std::string>& sets = st->sets;
  std::vector<std::string>& plugins = st->plugins;

  auto* validate = app.add_subcommand("validate", "Check a graph file; print every problem (exit 2) or OK");
  validate->add_option("graph", run.graph_path, "Graph YAML file")->required();
  validate->add_option("--set", sets, kSetHelp);
  auto* validate_plugins = validate->add_option("--plugins", plugins, "Extra plugin file or folder (repeatable)");
  validate->add_flag("--no-plugins", st->no_plugins,
                     "Load no plugin but dyad's built-in ones (a graph's plugins: are code: check an untrusted graph "
                     "without running it); components of other types are noted as not checked")
      ->excludes(validate_plugins);
  validate->callback([st, &exit_code] {
    exit_code = ValidateGraphFile(st->run.graph_path, ToOverrides(st->sets), st->plugins, std::cout, std::cerr,
                                  st->no_plugins ? PluginLoading::kBuiltinOnly : PluginLoading::kAll);
  });

  AddRunCommand(app, [&exit_code](const RunOptions& options) { exit_code = RunGraph(options, std::cout, std::cerr); });

  AddGraphCommand(app, exit_code);

  auto* ds = app.add_subcommand("discovery-server", "Run a Fast DDS discovery server for graphs with network.discovery: server");
  ds->add_option("--listen", st->listen, "ADDRESS:PORT to listen on (UDP)")->required();
  ds->callback([st, &exit_code] { exit_code = RunDiscoveryServer(st->listen, std::cout, std::cerr); });

  auto* types = app.add_subcommand("types", "List every component type found, with its ports and parameters");
  types->add_option("--plugins", plugins, "Extra plugin file or folder (repeatable)");
  types->add_option("names", st->type_names, "Only these component types");
  types->add_flag("--markdown", st->markdown, "Reference tables in Markdown (what docs/components.md embeds)");
  types->add_flag("--messages", st->messages, "The message types and their fields instead (with --markdown: docs/messages.md)");
  types->callback([st, &exit_code] {
    Catalog catalog;
    Status s = catalog.LoadDefault(st->plugins);
    if (!s.ok()) std::cerr << "warning: " << s.message() << "\n";
    exit_code = tools::Code(kOk);
    if (st->messages) {
      if (st->markdown) {
        std::cout << MessageReferenceMarkdown(catalog);
      } else {
        for (const TypeInfo* t : catalog.MessageTypes()) std::cout << t->short_name() << "  (" << t->dds_name() << ")\n";
      }
      return;
    }
    for (const std::string& n : st->type_names) {
      if (catalog.Find(n) == nullptr) {
        std::cerr << "dyad types: no component type '" << n << "' (dyad types lists them)\n";
        exit_code = tools::Code(kBadInput);
      }
    }
    if (exit_code != tools::Code(kOk)) return;
    std::ostringstream listed;
    for (const auto& [name, e] : catalog.entries()) {
      if (!st->type_names.empty() && std::find(st->type_names.begin(), st->type_names.end(), name) == st->type_names.end())
        continue;
      if (st->markdown) listed << ComponentReferenceMarkdown(name, e) << "\n";
      else PrintType(name, e, listed);
    }
    std::cout << listed.str();
    exit_code = tools::Code(catalog.entries().empty() ? kFailure : kOk);
  });
}

CLI::App* AddRunCommand(CLI::App& app, std::function<void(const RunOptions&)> on_run) {
  // Per registration, as in AddRuntimeCommands.
  struct State {
    RunOptions run;
    std::vector<std::string> sets, plugins;
  };
  auto st = std::make_shared<State>();
  RunOptions& run = st->run;
  std::vector<std::string>& sets = st->sets;
  std::vector<std::string>& plugins = st->plugins;
  auto* r = app.add_subcommand("run", "Run a graph (the components of one process, or launch every process)");
  r->add_option("graph", run.graph_path, "Graph YAML file")->required();
  r->add_option("--process", run.process, "Run only the components placed in this process");
  r->add_option("--logs", run.logs_dir, "Folder for each process's log (<process>.log); default: the graph's logs:");
  r->add_option("--host", run.host,
                "This machine's name in the graph (processes: NAME: {host: ...}); default: the host its keystore "
                "subset was exported for (a secured graph), else its host name");
  r->add_option("--set", sets, kSetHelp);
  r->add_option("--plugins", plugins, "Extra plugin file or folder (repeatable)");
  r->add_option("--duration", run.duration_s, "Stop after this many seconds of wall time")->check(CLI::NonNegativeNumber);
  r->add_option("--steps", run.steps, "Stop after the fastest periodic component ran this many steps");
  r->add_option("--stats-period", run.stats_period_s, "Seconds between ComponentStats samples on dyad/stats")
      ->check(CLI::PositiveNumber);
  r->add_option("--run-id", run.run_id,
                "This run's id: with the graph's name, the DDS partition that keeps it apart from other runs on the domain "
                "(default: a fresh one for a graph on one host, 'shared' for a graph on several; give the same one on every host)");
  r->add_flag("--quiet", run.quiet, "Do not print the timing table at exit");
  r->add_flag("--strict", run.strict, "A component that never stepped is an error (exit 1), not only a warning");
  // The launcher's, for a process it restarts: not in --help.
  r->add_option("--restart-count", run.restart_count, "How often the launcher restarted this process (with --process)")
      ->group("");
  r->callback([st, on_run = std::move(on_run)] {
    RunOptions options = st->run;
    options.overrides = ToOverrides(st->sets);
    options.plugin_paths = st->plugins;
    on_run(options);
  });
  return r;
}

}  // namespace dyad::cli
