#include "guest_commands.hpp"

#include <CLI/CLI.hpp>

#include <pwd.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include <dyad/cdr_decoder.hpp>
#include <dyad/cdr_encoder.hpp>
#include <dyad/guest.hpp>
#include <dyad/mcap/reader.hpp>
#include <dyad/security.hpp>
#include <dyad/topic_select.hpp>

#include "exit_code.hpp"
#include "watcher_catalog.hpp"

namespace dyad::cli {

using enum tools::ExitCode;
namespace {

// Owned by one registration (one per CLI::App), not function statics.
struct GuestState {
  IntrospectOptions opts;
  std::string graph, host, file, output = "{graph}-{time}.mcap", topic, fields = "{}", type;
  uint64_t count = 0;
  std::vector<std::string> topics, plugins;
  double duration = 0, rate = 0, start = 0;
  bool loop = false, overwrite = false;
  CLI::Option* domain = nullptr;
};

// The options a guest shares with the watchers: how it finds and joins the graph.
void AddJoinOptions(CLI::App* c, GuestState* st) {
  c->add_option("--graph", st->graph, "The graph to visit: its name, domain, network, security, topics and their QoS");
  st->domain = c->add_option("--domain", st->opts.domain_id, "DDS domain id (default: the --graph's, else 0)")->check(CLI::Range(0, 232));
  c->add_option("--run-id", st->opts.run_id, "Visit only this run of the --graph (its `dyad run --run-id`); default: every run");
  c->add_option("--host", st->host, "With --graph and its security: section: this machine's host in the graph (default: the machine's name)");
  c->add_option("--wait", st->opts.wait_s, "Seconds to wait for the graph's endpoints before starting anyway; default 5")->check(CLI::NonNegativeNumber);
  c->add_option("--plugins", st->plugins, "Plugin file or folder whose message types to know (repeatable)");
}

// The topics some component of `graph` binds as an output (writes: true) or an input.
std::vector<std::string> BoundTopics(const Graph& graph, bool writes) {
  std::set<std::string> topics;
  for (const auto& c : graph.components)
    for (const auto& port : writes ? c.outputs : c.inputs)
      if (!port.topic.empty()) topics.insert(port.topic);
  return {topics.begin(), topics.end()};
}

std::vector<std::string> Intersect(const std::vector<std::string>& a, const std::vector<std::string>& b) {
  std::vector<std::string> both;
  for (const auto& x : a)
    if (std::find(b.begin(), b.end(), x) != b.end()) both.push_back(x);
  return both;
}

// In a secured graph, `dyad pub` and `dyad bag play` publish as the graph's guest identity
// (dyad/security.hpp) and only what `security.guests.publish` grants: a topic outside the grant
// is refused here, before any participant is made, naming the key to change. Returns false
// having said why; true with st->opts.security set to the guest's files (or for an open graph).
bool PublishAsGuest(const std::optional<Graph>& graph, const std::vector<std::string>& topics, const std::string& tool,
                    GuestState* st) {
  if (!graph || !graph->security.enabled()) return true;
  const SecurityConfig& sec = graph->security;
  const std::string init = "rerun `dyad security init " + sec.keystore + " --graph " + st->graph + "`";
  if (!sec.guests) {
    std::cerr << tool << ": graph '" << graph->name << "' is secured and lets no guest publish: add `guests: {publish: ["
              << (topics.empty() ? "TOPIC" : topics.front()) << "]}` under security: (" << sec.mark.ToString() << "), then "
              << init << "\n";
    return false;
  }
  bool ok = true;
  for (const std::string& t : topics)
    if (!TopicGranted(sec.guest_publish, t)) {
      std::cerr << tool << ": topic '" << t << "': the graph's guests may not publish it: add it to security.guests.publish ("
                << sec.guests_mark.ToString() << "), then " << init << "\n";
      ok = false;
    }
  if (Status s = CheckIdentityHeld(*graph, kGuestIdentity); ok && !s.ok()) {
    std::cerr << tool << ": " << s.message() << "\n";
    ok = false;
  }
  if (ok) st->opts.security = IdentityOf(*graph, kGuestIdentity);
  return ok;
}

// A guest of one component `name` of `type`, stepping at `rate_hz`, with `params`.
GuestOptions OneComponentGuest(const GuestState& st, const std::string& label, const std::string& name, const std::string& type,
                               int rate_hz, const YAML::Node& params) {
  YAML::Node components;
  components[name]["type"] = type;
  components[name]["rate_hz"] = rate_hz;
  components[name]["params"] = params;
  YAML::Emitter e;
  e << YAML::Flow << components;
  GuestOptions go;
  go.watch = st.opts;
  go.label = label;
  go.components_yaml = e.c_str();
  go.duration_s = st.duration;
  return go;
}

// `dyad record` as the graph's guest: what it records must be granted by security.guests.subscribe.
// With no topics named: every topic the graph writes that the grant covers (the others named on
// stderr). False, having said why, when a named topic is not granted or nothing is.
bool GuestTopics(const Graph& graph, GuestState* st) {
  if (!st->topics.empty()) return GuestMayRead(graph, st->graph, st->topics, "dyad record");
  std::vector<std::string> left_out;
  for (const std::string& t : BoundTopics(graph, true))
    (TopicGranted(graph.security.guest_subscribe, t) ? st->topics : left_out).push_back(t);
  if (st->topics.empty()) return GuestMayRead(graph, st->graph, left_out, "dyad record");
  for (const std::string& t : left_out)
    std::cerr << "dyad record: not recording '" << t << "': the graph's guests may not read it (security.guests.subscribe)\n";
  return true;
}

int Record(GuestState& st) {
  Catalog catalog;
  std::optional<Graph> graph;
  bool as_guest = false;
  if (!LoadWatcherCatalog(st.graph, st.plugins, &catalog, &st.opts, st.domain->count() > 0, st.host, &graph, &as_guest))
    return tools::Code(kBadInput);
  if (as_guest && !GuestTopics(*graph, &st)) return tools::Code(kBadInput);
  if (st.topics.empty() && !graph) {
    std::cerr << "dyad record: name the topics to record, or give --graph G to record every topic of G\n";
    return tools::Code(kBadInput);
  }
  YAML::Node params;
  params["file"] = std::filesystem::absolute(st.output).string();
  params["overwrite"] = st.overwrite;
  params["topics"] = YAML::Node(YAML::NodeType::Sequence);
  for (const auto& t : st.topics) params["topics"].push_back(t);
  GuestOptions go = OneComponentGuest(st, "dyad record", "record", "recorder", 10, params);
  if (graph) {
    go.watched = &*graph;
    const std::vector<std::string> written = BoundTopics(*graph, true);
    go.await_writers = st.topics.empty() ? written : Intersect(st.topics, written);
  } else {
    go.discover = st.topics;  // found once a writer is: nothing more to wait for
  }
  return RunGuest(go, catalog, std::cout, std::cerr);
}

int Play(GuestState& st) {
  Catalog catalog;
  std::optional<Graph> graph;
  bool as_guest = false;  // (they publish as the guest anywhere: PublishAsGuest)
  if (!LoadWatcherCatalog(st.graph, st.plugins, &catalog, &st.opts, st.domain->count() > 0, st.host, &graph, &as_guest))
    return tools::Code(kBadInput);
  // The topics to play, chosen here as the replay will: to know which readers to wait for. The
  // runtime's own topics (dyad/...) are left out unless named: a recorded dyad/processes played
  // into a live graph would tell its watchers of processes that are not there.
  auto reader = mcap::Reader::Open(st.file);
  if (!reader.ok()) {
    std::cerr << "dyad bag play: " << reader.status().message() << "\n";
    return tools::Code(kBadInput);
  }
  std::vector<std::string> recorded, runtime_topics;
  for (const auto& [id, ch] : reader->channels())
    if (std::find(recorded.begin(), recorded.end(), ch.topic) == recorded.end()) {
      recorded.push_back(ch.topic);
      if (ch.topic.rfind("dyad/", 0) == 0) runtime_topics.push_back(ch.topic);
    }
  auto chosen = SelectTopics(st.topics, recorded, "--topics", runtime_topics);
  if (!chosen.ok()) {
    std::cerr << "dyad bag play: " << st.file << ": " << chosen.status().message() << "\n";
    return tools::Code(kBadInput);
  }
  if (chosen->empty()) {
    std::cerr << "dyad bag play: " << st.file << ": no topic to play (its topics: " << recorded.size() << ", all of the runtime's)\n";
    return tools::Code(kBadInput);
  }
  YAML::Node params;
  params["file"] = std::filesystem::absolute(st.file).string();
  params["topics"] = YAML::Node(YAML::NodeType::Sequence);
  for (const auto& t : *chosen) params["topics"].push_back(t);
  params["speed"] = st.rate > 0 ? st.rate : 1.0;
  params["loop"] = st.loop;
  params["start_s"] = st.start;
  // 1000 Hz: each sample within a millisecond of its recorded spacing.
  if (!PublishAsGuest(graph, *chosen, "dyad bag play", &st)) return tools::Code(kBadInput);
  GuestOptions go = OneComponentGuest(st, "dyad bag play", "play", "replay", 1000, params);
  go.watched = graph ? &*graph : nullptr;
  // A reader of each played topic: a component's input, a recorder's subscription, a watcher's.
  go.await_readers = *chosen;
  return RunGuest(go, catalog, std::cout, std::cerr);
}

// Sample i of `type` from the YAML `fields`; a dyad header the fields leave out is filled in
// (source "dyad/pub", sequence_number i + 1, stamp_ns now), as a component's Output would. The
// node the person wrote is encoded itself (not a copy): its marks place errors at their column.
SampleMaker YamlSamples(const std::string& fields) {
  struct Parsed {
    YAML::Node node;
    std::optional<cdr::Schema> schema;
    bool fill_source = false, fill_sequence = false, fill_stamp = false;
  };
  auto p = std::make_shared<Parsed>();
  return [fields, p](const TypeInfo& type, uint64_t index) -> StatusOr<std::vector<uint8_t>> {
    if (!p->schema) {
      try {
        p->node = YAML::Load(fields);
      } catch (const YAML::Exception& e) {
        return Status::InvalidArgument("the fields are not YAML: line " + std::to_string(e.mark.line + 1) + ", column " +
                                       std::to_string(e.mark.column + 1) + ": " + e.msg);
      }
      if (p->node.IsNull()) p->node = YAML::Node(YAML::NodeType::Map);
      auto parsed = cdr::Schema::Parse(type.idl);
      if (!parsed.ok()) return Status::Internal(type.name + ": its IDL does not parse: " + parsed.status().message());
      p->schema = std::move(parsed).value();
      const std::vector<std::string> columns = cdr::Columns(*p->schema, type.name);
      if (p->node.IsMap() && std::find(columns.begin(), columns.end(), "header.sequence_number") != columns.end()) {
        if (!p->node["header"]) p->node["header"] = YAML::Node(YAML::NodeType::Map);
        const YAML::Node header = p->node["header"];
        if (header.IsMap()) {
          p->fill_source = !header["source"];
          p->fill_sequence = !header["sequence_number"];
          p->fill_stamp = !header["stamp_ns"];
        }
      }
    }
    if (p->fill_source || p->fill_sequence || p->fill_stamp) {  // (so a node that is no mapping is left alone)
      YAML::Node header = p->node["header"];
      if (p->fill_source) header["source"] = "dyad/pub";
      if (p->fill_sequence) header["sequence_number"] = index + 1;
      if (p->fill_stamp)
        header["stamp_ns"] = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
    }
    auto bytes = cdr::EncodeYaml(*p->schema, type.name, p->node);
    if (!bytes.ok()) return Status::InvalidArgument("the fields: " + bytes.status().message());
    return bytes;
  };
}

int Pub(GuestState& st) {
  Catalog catalog;
  std::optional<Graph> graph;
  bool as_guest = false;  // (they publish as the guest anywhere: PublishAsGuest)
  if (!LoadWatcherCatalog(st.graph, st.plugins, &catalog, &st.opts, st.domain->count() > 0, st.host, &graph, &as_guest))
    return tools::Code(kBadInput);
  if (!PublishAsGuest(graph, {st.topic}, "dyad pub", &st)) return tools::Code(kBadInput);
  PublishOptions po;
  po.watch = st.opts;
  po.watched = graph ? &*graph : nullptr;
  po.topic = st.topic;
  po.type_name = st.type;
  po.rate_hz = st.rate;
  // One sample, unless a rate asks for a stream (then until Ctrl-C, or --count).
  po.count = st.count > 0 ? st.count : (st.rate > 0 ? 0 : 1);
  return PublishTopic(po, catalog, YamlSamples(st.fields), std::cout, std::cerr);
}

// `dyad param get C.P` / `set C.P=V`: the request, split and checked for its shape.
int Param(GuestState& st, bool set) {
  const std::string& text = st.topic;  // the positional argument
  const size_t eq = set ? text.find('=') : std::string::npos;
  const std::string name = set ? text.substr(0, eq) : text;
  const size_t dot = name.find('.');
  if ((set && eq == std::string::npos) || dot == std::string::npos || dot == 0 || dot + 1 == name.size()) {
    std::cerr << "dyad param: '" << text << "': expected COMPONENT.PARAM" << (set ? "=VALUE" : "") << " (e.g. mixer.gain"
              << (set ? "=0.5" : "") << ")\n";
    return tools::Code(kBadInput);
  }
  if (st.graph.empty()) {
    std::cerr << "dyad param: --graph is required (it names the component's process and its parameters)\n";
    return tools::Code(kBadInput);
  }
  Catalog catalog;
  std::optional<Graph> graph;
  if (!LoadWatcherCatalog(st.graph, st.plugins, &catalog, &st.opts, st.domain->count() > 0, st.host, &graph))
    return tools::Code(kBadInput);
  ParamRequest r;
  r.watch = st.opts;
  r.watched = &*graph;
  r.component = name.substr(0, dot);
  r.param = name.substr(dot + 1);
  r.set = set;
  if (set) r.value = text.substr(eq + 1);
  r.who = ParamRequester();
  return RequestParam(r, catalog, std::cout, std::cerr);
}

}  // namespace

std::string ParamRequester() {
  std::string user;
  if (const char* env = std::getenv("USER"); env != nullptr) user = env;
  if (user.empty()) {
    std::vector<char> buf(16384);
    passwd pw{};
    passwd* found = nullptr;
    if (getpwuid_r(getuid(), &pw, buf.data(), buf.size(), &found) == 0 && found != nullptr && found->pw_name != nullptr)
      user = found->pw_name;
  }
  char host[256] = {0};
  gethostname(host, sizeof(host) - 1);
  return "dyad param (" + (user.empty() ? std::string("?") : user) + "@" + host + ")";
}

void AddGuestCommands(CLI::App& app, int& exit_code) {
  auto st = std::make_shared<GuestState>();

  auto* record = app.add_subcommand("record", "Record topics of a running graph into an MCAP file, as a guest (ros2 bag record)");
  record->add_option("topics", st->topics, "Topics to record (names or regexes); none: every topic of the --graph");
  record->add_option("-o,--output", st->output, "The recording; {graph} and {time} are expanded as the recorder does (default {graph}-{time}.mcap)");
  record->add_option("--duration", st->duration, "Stop after this many seconds (default: at Ctrl-C)")->check(CLI::NonNegativeNumber);
  record->add_flag("--overwrite", st->overwrite, "Replace an existing file (default: an existing file is an error)");
  AddJoinOptions(record, st.get());
  record->callback([st, &exit_code] { exit_code = Record(*st); });

  auto* pub = app.add_subcommand("pub", "Publish samples on a topic of a running graph, fields given as YAML (ros2 topic pub)");
  pub->add_option("topic", st->topic, "The topic")->required();
  pub->add_option("fields", st->fields, "The sample's fields as YAML, e.g. '{x: 0.5, y: -0.25, engaged: true}'; left out: zero (a dyad header is filled in)");
  pub->add_option("--type", st->type, "The topic's message type (default: the --graph's, else its discovered endpoints')");
  pub->add_option("-r,--rate", st->rate, "Samples per second (default: one sample, unless --count)")->check(CLI::PositiveNumber);
  pub->add_option("-n,--count", st->count, "How many samples (default: 1; with --rate, until Ctrl-C)");
  AddJoinOptions(pub, st.get());
  pub->callback([st, &exit_code] { exit_code = Pub(*st); });

  auto* param = app.add_subcommand("param", "Get or set a live parameter of a running graph's component (ros2 param get|set)");
  param->require_subcommand(1);
  auto* get = param->add_subcommand("get", "Print a live parameter's value: dyad param get mixer.gain --graph G");
  get->add_option("name", st->topic, "COMPONENT.PARAM")->required();
  AddJoinOptions(get, st.get());
  get->callback([st, &exit_code] { exit_code = Param(*st, false); });
  auto* set = param->add_subcommand("set", "Change a live parameter at the component's next step: dyad param set mixer.gain=0.5 --graph G");
  set->add_option("assignment", st->topic, "COMPONENT.PARAM=VALUE (VALUE in YAML: 0.5, [1e-4, 1e-3], text)")->required();
  AddJoinOptions(set, st.get());
  set->callback([st, &exit_code] { exit_code = Param(*st, true); });

  CLI::App* bag = app.get_subcommand("bag");
  auto* play = bag->add_subcommand("play", "Publish a recording's samples onto a running graph's topics, with their recorded spacing (ros2 bag play)");
  play->add_option("file", st->file, "The MCAP recording")->required();
  play->add_option("--topics", st->topics, "Recorded topics to play (names or regexes); default: all but the runtime's (dyad/...)");
  play->add_option("--rate", st->rate, "Time scale (2: twice as fast)")->check(CLI::PositiveNumber);
  play->add_flag("--loop", st->loop, "Start over after the last sample, until Ctrl-C or --duration");
  play->add_option("--start", st->start, "Skip the recording's first seconds")->check(CLI::NonNegativeNumber);
  play->add_option("--duration", st->duration, "Stop after this many seconds")->check(CLI::NonNegativeNumber);
  AddJoinOptions(play, st.get());
  play->callback([st, &exit_code] { exit_code = Play(*st); });
}

}  // namespace dyad::cli
