#include "introspection_commands.hpp"

#include <CLI/CLI.hpp>
#include "watcher_catalog.hpp"

#include <iomanip>
#include <map>
#include <memory>
#include <optional>
#include <iostream>
#include <sstream>

#include <dyad/cdr_decoder.hpp>
#include <dyad/graph.hpp>
#include <dyad/introspect.hpp>

#include "exit_code.hpp"

namespace dyad::cli {

using enum tools::ExitCode;
namespace {

// Prints samples as JSON, decoded with each type's own IDL text (parsed once per type); as hex
// with the reason when that fails.
SamplePrinter JsonPrinter() {
  auto schemas = std::make_shared<std::map<std::string, StatusOr<cdr::Schema>>>();
  return [schemas](const TypeInfo& type, const uint8_t* data, size_t size) {
    auto it = schemas->find(type.name);
    if (it == schemas->end()) it = schemas->emplace(type.name, cdr::Schema::Parse(type.idl)).first;
    const StatusOr<cdr::Schema>& schema = it->second;
    std::vector<cdr::Field> fields;
    const Status decoded = schema.ok() ? cdr::Decode(*schema, type.name, data, size, &fields) : schema.status();
    if (decoded.ok()) return cdr::ToJson(fields);
    std::ostringstream os;
    os << type.short_name() << " (" << decoded.message() << ") " << size << " bytes:";
    for (size_t i = 0; i < size; ++i) os << (i % 4 == 0 ? " " : "") << std::hex << std::setw(2) << std::setfill('0') << int(data[i]);
    return os.str();
  };
}

// What the watcher commands' options fill in, shared by their callbacks: one per registration
// (one per CLI::App), not function statics.
struct WatchState {
  IntrospectOptions opts;
  std::string topic;
  uint64_t count = 0;
  double duration = 0;
  std::vector<std::string> plugins;
  std::string graph;
  std::string host;
  std::vector<CLI::Option*> domain_options;

  bool domain_given() const {
    for (auto* o : domain_options)
      if (o->count() > 0) return true;
    return false;
  }

  // The options every watcher command has: --domain, --run-id, --host, --wait.
  void AddCommonOptions(CLI::App* c) {
    domain_options.push_back(c->add_option("--domain", opts.domain_id, "DDS domain id (default: the --graph's, else 0)")->check(CLI::Range(0, 232)));
    c->add_option("--run-id", opts.run_id, "Watch only this run of the --graph (its `dyad run --run-id`); default: every run");
    c->add_option("--host", host, "With --graph and its security: section: this machine's host in the graph, whose identity the watcher uses (default: the machine's name)");
    c->add_option("--wait", opts.wait_s, "Seconds of discovery before answering (topics) or giving up on a topic (echo, hz); default 5")->check(CLI::NonNegativeNumber);
  }

  // The catalog, domain and network a watcher joins with, and the --graph it watches; false
  // (exit 2) when the graph cannot be read, having said why.
  // A watcher of one topic (`reads_topic`: echo, hz) on a machine that is none of a secured
  // graph's hosts joins as its guest, if the graph grants its guests that topic.
  bool Join(Catalog* catalog, std::optional<Graph>* watched, const char* reads_topic = nullptr) {
    bool as_guest = false;
    if (!LoadWatcherCatalog(graph, plugins, catalog, &opts, domain_given(), host, watched, reads_topic ? &as_guest : nullptr))
      return false;
    return !as_guest || GuestMayRead(**watched, graph, {topic}, reads_topic);
  }

  // The topic a watcher reads: a ROS 2 topic of the --graph by its ROS 2 name (what it is on the
  // wire, where every ROS 2 program sees it).
  std::string WatchedTopic(const std::optional<Graph>& watched) const {
    const TopicConfig* t = watched ? watched->FindTopic(topic) : nullptr;
    return t && !t->ros2.empty() ? t->ros2 : topic;
  }
};

// `dyad topics` and `dyad status`: what is on the domain.
void AddDomainCommands(CLI::App& app, const std::shared_ptr<WatchState>& st, int& exit_code) {
  auto* topics = app.add_subcommand("topics", "List the topics on the DDS domain with their types and endpoints");
  st->AddCommonOptions(topics);
  topics->add_option("--graph", st->graph, "The graph (its domain and network); ends as soon as its topics and processes are found");
  topics->callback([st, &exit_code] {
    Catalog catalog;
    std::optional<Graph> graph;
    if (!st->Join(&catalog, &graph)) {
      exit_code = tools::Code(kBadInput);
      return;
    }
    exit_code = ListTopics(st->opts, std::cout, graph ? &*graph : nullptr);
  });

  auto* status = app.add_subcommand("status", "Every process of a running graph: host, pid, state, restarts, clock offsets, step stats");
  st->AddCommonOptions(status);
  status->add_option("--graph", st->graph, "The graph (its name, domain and network); default: every graph on the domain. Ends as soon as it has heard all of it");
  status->callback([st, &exit_code] {
    Catalog catalog;
    std::optional<Graph> graph;
    if (!st->Join(&catalog, &graph)) {
      exit_code = tools::Code(kBadInput);
      return;
    }
    exit_code = ShowStatus(st->opts, graph ? &*graph : nullptr, std::cout, std::cerr);
  });
}

// `dyad echo` and `dyad hz`: one topic's samples.
void AddTopicCommands(CLI::App& app, const std::shared_ptr<WatchState>& st, int& exit_code) {
  auto* echo = app.add_subcommand("echo", "Print the samples published on a topic");
  st->AddCommonOptions(echo);
  echo->add_option("topic", st->topic, "Topic name")->required();
  echo->add_option("-n,--count", st->count, "Stop after this many samples (0: until Ctrl-C)");
  echo->add_option("--duration", st->duration, "Stop after this many seconds");
  echo->add_option("--plugins", st->plugins, "Plugin file or folder whose message types to know (repeatable)");
  echo->add_option("--graph", st->graph, "Know the message types of this graph's plugins");
  echo->callback([st, &exit_code] {
    Catalog catalog;
    std::optional<Graph> graph;
    if (!st->Join(&catalog, &graph, "dyad echo")) {
      exit_code = tools::Code(kBadInput);
      return;
    }
    exit_code = EchoTopic(st->opts, catalog, st->WatchedTopic(graph), st->count, st->duration, JsonPrinter(), std::cout, std::cerr);
  });

  auto* hz = app.add_subcommand("hz", "Measure the publication rate of a topic");
  st->AddCommonOptions(hz);
  hz->add_option("topic", st->topic, "Topic name")->required();
  hz->add_option("--duration", st->duration, "Stop after this many seconds (0: until Ctrl-C)");
  hz->add_option("--plugins", st->plugins, "Plugin file or folder whose message types to know (repeatable)");
  hz->add_option("--graph", st->graph, "Know the message types of this graph's plugins");
  hz->callback([st, &exit_code] {
    Catalog catalog;
    std::optional<Graph> graph;
    if (!st->Join(&catalog, &graph, "dyad hz")) {
      exit_code = tools::Code(kBadInput);
      return;
    }
    exit_code = TopicHz(st->opts, catalog, st->WatchedTopic(graph), st->duration, std::cout, std::cerr);
  });
}

}  // namespace

void AddIntrospectionCommands(CLI::App& app, int& exit_code) {
  auto st = std::make_shared<WatchState>();
  AddDomainCommands(app, st, exit_code);
  AddTopicCommands(app, st, exit_code);
}

}  // namespace dyad::cli
