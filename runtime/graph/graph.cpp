// Reads an experiment graph from YAML, keeping every node's position for error messages.
#include "dyad/graph.hpp"
#include "dyad/join_list.hpp"
#include "dyad/ros2_names.hpp"
#include "dyad/strict_yaml.hpp"
#include "dyad/wire_names.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>


#include "graph/graph_document.hpp"
#include "graph/graph_keys.hpp"
#include "graph/host_port.hpp"
#include "graph/network_scope.hpp"
#include "graph/run_partition.hpp"

namespace dyad {
namespace {

// Graph names become part of DDS partition names (graph/run_partition.hpp).
const std::string kGraphNameRule = "must be 1 to 64 of the characters A-Z a-z 0-9 _ . - (it names the run's DDS partition)";

// Process and host names become file names (a process's log: <log dir>/<process>.log) and
// DDS participant names: no '/', no '.', nothing a shell or a path would read twice.
const std::string kPlaceNameRule =
    "must be 1 to 64 of the characters A-Z a-z 0-9 _ -, not starting with - (it names a log file and a DDS participant)";
constexpr size_t kMaxPlaceName = 64;
bool IsPlaceName(const std::string& s) {
  if (s.empty() || s.size() > kMaxPlaceName || s[0] == '-') return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

// Every participant name the graph makes is read back by its secured peers (dyad/wire_names.hpp):
// dyad/<graph>/<process> and dyad/launcher/<host>, each name at most 64 characters.
static_assert(5 + 64 + 1 + kMaxPlaceName <= kMaxReadableName, "dyad/<graph>/<process> must fit a wire name");
static_assert(sizeof("dyad/launcher/") - 1 + kMaxPlaceName <= kMaxReadableName, "dyad/launcher/<host> must fit a wire name");

// A process's host outside network.hosts (whose names are place names) may be any machine name
// (dots included), of at most 64 characters as Linux's (HOST_NAME_MAX).
std::string LongHostProblem(const std::string& host) {
  return "'" + host.substr(0, 20) + "...' has " + std::to_string(host.size()) + " characters: a host name has at most " +
         std::to_string(kMaxPlaceName) + " (as a machine's name; its launcher's DDS participant dyad/launcher/<host> must fit " +
         std::to_string(kMaxReadableName) + " bytes, the longest name a secured graph's participants read back)";
}

std::string Names(const std::map<std::string, std::string>& m) {
  return JoinList(m, [](const auto& kv) -> const std::string& { return kv.first; });
}

void ReadStringList(StrictYaml& r, const YAML::Node& node, const std::string& key, std::vector<std::string>* out) {
  if (!node.IsSequence()) {
    r.Error(node, key, "must be a list");
    return;
  }
  for (const auto& item : node) {
    std::string s;
    if (r.String(item, key, &s)) out->push_back(s);
  }
}

void ReadNetwork(StrictYaml& r, const YAML::Node& node, NetworkConfig* n) {
  n->mark = r.Mark(node, "network");
  if (node.IsNull()) return;
  if (!r.Map(node, "network", graph_keys::kNetwork)) return;
  std::string s;
  if (node["discovery"] && r.String(node["discovery"], "network.discovery", &s)) {
    if (s == "multicast") n->discovery = Discovery::kMulticast;
    else if (s == "peers") n->discovery = Discovery::kPeers;
    else if (s == "server") n->discovery = Discovery::kServer;
    else r.Error(node["discovery"], "network.discovery", "must be multicast, peers or server, got '" + s + "'");
  }
  if (const YAML::Node hosts = node["hosts"]; hosts && r.Map(hosts, "network.hosts", {})) {
    for (const auto& kv : hosts) {
      if (!IsPlaceName(kv.first.Scalar()))
        r.Error(kv.first, "network.hosts." + kv.first.Scalar(), kPlaceNameRule + (", got '" + kv.first.Scalar() + "'"));
      std::string address;
      if (r.String(kv.second, "network.hosts." + kv.first.Scalar(), &address)) n->hosts[kv.first.Scalar()] = address;
    }
  }
  if (node["peers"]) {
    ReadStringList(r, node["peers"], "network.peers", &n->peers);
    for (const auto& p : n->peers) {
      HostPort hp;
      if (!ParseHostPort(p, &hp, false))
        r.Error(node["peers"], "network.peers", "'" + p + "' is not address or address:port (port 1..65535)");
    }
  }
  if (node["server"] && r.String(node["server"], "network.server", &n->server)) {
    HostPort hp;
    const bool valid = ParseHostPort(n->server, &hp, true);
    const std::string& host = hp.host;
    n->server_port = hp.port;
    if (!valid) {
      r.Error(node["server"], "network.server", "must be HOST:PORT (HOST a name of network.hosts or an address), got '" + n->server + "'");
    } else if (auto it = n->hosts.find(host); it != n->hosts.end()) {
      n->server_host = host;
      n->server_address = it->second;
    } else {
      n->server_address = host;
    }
  }
  if (node["transport"] && r.String(node["transport"], "network.transport", &s)) {
    if (s == "shm+udp") n->transport = NetTransport::kShmUdp;
    else if (s == "udp") n->transport = NetTransport::kUdp;
    else if (s == "tcp") n->transport = NetTransport::kTcp;
    else r.Error(node["transport"], "network.transport", "must be shm+udp, udp or tcp, got '" + s + "'");
  }
  if (node["interfaces"]) ReadStringList(r, node["interfaces"], "network.interfaces", &n->interfaces);
  if (node["launcher_tcp_port"] &&
      r.Get(node["launcher_tcp_port"], "network.launcher_tcp_port", &n->launcher_tcp_port, "an integer") &&
      (n->launcher_tcp_port < 1 || n->launcher_tcp_port > 65535))
    r.Error(node["launcher_tcp_port"], "network.launcher_tcp_port", "must be in 1..65535");
  if (node["lease_s"] && r.Get(node["lease_s"], "network.lease_s", &n->lease_s, "a number") && !(n->lease_s >= 1))
    r.Error(node["lease_s"], "network.lease_s", "must be >= 1 (a shorter lease declares live processes gone)");
  if (node["start_timeout_s"] && r.Get(node["start_timeout_s"], "network.start_timeout_s", &n->start_timeout_s, "a number") &&
      !(n->start_timeout_s > 0))
    r.Error(node["start_timeout_s"], "network.start_timeout_s", "must be > 0");
  if (node["max_clock_offset_ms"] &&
      r.Get(node["max_clock_offset_ms"], "network.max_clock_offset_ms", &n->max_clock_offset_ms, "a number") &&
      !(n->max_clock_offset_ms > 0))
    r.Error(node["max_clock_offset_ms"], "network.max_clock_offset_ms", "must be > 0");
  if (n->discovery == Discovery::kPeers && n->peers.empty() && n->hosts.empty())
    r.Error(node["discovery"], "network.discovery", "peers: needs network.peers or network.hosts (the addresses to announce to)");
  if (n->transport == NetTransport::kTcp && n->discovery != Discovery::kPeers)
    r.Error(node["transport"], "network.transport", "tcp: needs discovery: peers (TCP carries no multicast; each process "
                                                    "connects to the others' tcp_port)");
  if (n->discovery == Discovery::kServer && n->server.empty())
    r.Error(node["discovery"], "network.discovery", "server: needs network.server (HOST:PORT of the discovery server)");
}

// network.scope, given or implied (graph.hpp): a graph that points at no other machine is
// reachable from this machine only.
void ResolveScope(StrictYaml& r, const YAML::Node& network, Graph* g) {
  NetworkConfig& n = g->network;
  std::string why_lan;  // the first key that points at another machine
  if (g->PlacedOnHosts()) why_lan = "processes on hosts";
  else if (!n.hosts.empty()) why_lan = "network.hosts";
  else if (!n.peers.empty()) why_lan = "network.peers";
  else if (!n.server.empty()) why_lan = "network.server";
  else if (!n.interfaces.empty()) why_lan = "network.interfaces";
  else if (n.transport == NetTransport::kTcp) why_lan = "network.transport tcp";
  else if (n.discovery != Discovery::kMulticast) why_lan = "network.discovery";
  std::string s;
  // (`network: 5` or `network: [a]`, reported with the section: no scope to read in it.)
  if (!network || !network.IsMap() || !network["scope"] || !r.String(network["scope"], "network.scope", &s)) {
    n.scope = why_lan.empty() ? NetScope::kLocal : NetScope::kLan;
  } else if (s == "lan") {
    n.scope = NetScope::kLan;
  } else if (s == "local") {
    n.scope = NetScope::kLocal;
    if (!why_lan.empty())
      r.Error(network["scope"], "network.scope", "local: this machine only, but the graph points at others (" + why_lan + ")");
  } else {
    r.Error(network["scope"], "network.scope", "must be local (this machine only) or lan, got '" + s + "'");
  }
}

// `ros2:` and `qos:` (dyad/ros2_names.hpp): the profile's reliability and depth first, so that
// the entry's own `reliability:` and `depth:` override them.
void ReadRos2Topic(StrictYaml& r, const YAML::Node& spec, const std::string& key, TopicConfig* t) {
  if (spec["ros2"] && r.String(spec["ros2"], key + ".ros2", &t->ros2)) {
    t->ros2_mark = r.Mark(spec["ros2"], key + ".ros2");
    if (std::string why = Ros2TopicNameProblem(t->ros2); !why.empty())
      r.Error(spec["ros2"], key + ".ros2", "'" + t->ros2 + "' is not a ROS 2 topic name: it " + why);
  }
  if (!spec["qos"]) {
    if (!t->ros2.empty()) t->ros2_qos = "default";
  } else if (r.String(spec["qos"], key + ".qos", &t->ros2_qos)) {
    Ros2Qos profile;
    if (t->ros2.empty())
      r.Error(spec["qos"], key + ".qos", "names a ROS 2 QoS profile: only a ROS 2 topic (with ros2:) has one");
    else if (!Ros2QosProfile(t->ros2_qos, &profile))
      r.Error(spec["qos"], key + ".qos", "unknown ROS 2 QoS profile '" + t->ros2_qos + "' (known: " + JoinList(Ros2QosProfiles()) + ")");
  }
  Ros2Qos profile;
  if (!t->ros2.empty() && Ros2QosProfile(t->ros2_qos, &profile)) {
    t->reliability = profile.reliable ? Reliability::kReliable : Reliability::kBestEffort;
    t->depth = profile.depth;
  }
}

void ReadTopics(StrictYaml& r, const YAML::Node& node, Graph* g) {
  if (!r.Map(node, "topics", {})) return;
  for (const auto& kv : node) {
    TopicConfig t;
    t.name = kv.first.Scalar();
    const std::string key = "topics." + t.name;
    t.mark = r.Mark(kv.first, key);
    const YAML::Node spec = kv.second;
    if (spec.IsNull()) {
      g->topics.push_back(t);
      continue;
    }
    if (!r.Map(spec, key, graph_keys::kTopic)) continue;
    if (spec["type"]) {
      r.String(spec["type"], key + ".type", &t.type);
      t.type_mark = r.Mark(spec["type"], key + ".type");
    }
    ReadRos2Topic(r, spec, key, &t);
    if (spec["reliability"]) {
      std::string rel;
      if (r.String(spec["reliability"], key + ".reliability", &rel)) {
        if (rel == "reliable") t.reliability = Reliability::kReliable;
        else if (rel == "best_effort") t.reliability = Reliability::kBestEffort;
        else r.Error(spec["reliability"], key + ".reliability", "must be reliable or best_effort, got '" + rel + "'");
      }
    }
    if (spec["depth"] && r.Get(spec["depth"], key + ".depth", &t.depth, "an integer") && t.depth < 1)
      r.Error(spec["depth"], key + ".depth", "must be >= 1, got " + std::to_string(t.depth));
    if (spec["deadline_ms"] && r.Get(spec["deadline_ms"], key + ".deadline_ms", &t.deadline_ms, "a number") &&
        t.deadline_ms < 0)
      r.Error(spec["deadline_ms"], key + ".deadline_ms", "must be >= 0");
    if (spec["liveliness_ms"] && r.Get(spec["liveliness_ms"], key + ".liveliness_ms", &t.liveliness_ms, "a number") &&
        t.liveliness_ms < 0)
      r.Error(spec["liveliness_ms"], key + ".liveliness_ms", "must be >= 0");
    g->topics.push_back(t);
  }
}

void ReadBindings(StrictYaml& r, const YAML::Node& node, const std::string& key, std::vector<PortBinding>* out) {
  if (!r.Map(node, key, {})) return;
  for (const auto& kv : node) {
    PortBinding b;
    b.port = kv.first.Scalar();
    b.mark = r.Mark(kv.second, key + "." + b.port);
    if (r.String(kv.second, key + "." + b.port, &b.topic)) out->push_back(b);
  }
}

void ReadComponents(StrictYaml& r, const YAML::Node& node, Graph* g) {
  if (!r.Map(node, "components", {})) return;
  for (const auto& kv : node) {
    ComponentConfig c;
    c.name = kv.first.Scalar();
    const std::string key = "components." + c.name;
    c.mark = r.Mark(kv.first, key);
    const YAML::Node spec = kv.second;
    if (!r.Map(spec, key, graph_keys::kComponent)) continue;
    if (spec["type"]) {
      r.String(spec["type"], key + ".type", &c.type);
      c.type_mark = r.Mark(spec["type"], key + ".type");
    } else {
      r.Error(kv.first, key + ".type", "missing (every component names its type)");
    }
    if (spec["rate_hz"]) {
      c.rate_mark = r.Mark(spec["rate_hz"], key + ".rate_hz");
      if (r.Get(spec["rate_hz"], key + ".rate_hz", &c.rate_hz, "a number") && !(c.rate_hz > 0))
        r.Error(spec["rate_hz"], key + ".rate_hz", "must be > 0, got " + spec["rate_hz"].Scalar());
    }
    if (spec["trigger"]) {
      c.trigger_mark = r.Mark(spec["trigger"], key + ".trigger");
      r.String(spec["trigger"], key + ".trigger", &c.trigger);
    }
    if (spec["process"]) {
      c.process_mark = r.Mark(spec["process"], key + ".process");
      r.String(spec["process"], key + ".process", &c.process);
    }
    if (spec["params"]) {
      c.params_mark = r.Mark(spec["params"], key + ".params");
      if (spec["params"].IsNull()) c.params = YAML::Node(YAML::NodeType::Map);
      else if (r.Map(spec["params"], key + ".params", {})) c.params = spec["params"];
    } else {
      c.params = YAML::Node(YAML::NodeType::Map);
      c.params_mark = c.mark;
    }
    if (spec["inputs"] && !spec["inputs"].IsNull()) ReadBindings(r, spec["inputs"], key + ".inputs", &c.inputs);
    if (spec["outputs"] && !spec["outputs"].IsNull()) ReadBindings(r, spec["outputs"], key + ".outputs", &c.outputs);
    g->components.push_back(std::move(c));
  }
}

}  // namespace

const ComponentConfig* Graph::FindComponent(const std::string& n) const {
  for (const auto& c : components)
    if (c.name == n) return &c;
  return nullptr;
}

const TopicConfig* Graph::FindTopic(const std::string& n) const {
  for (const auto& t : topics)
    if (t.name == n) return &t;
  return nullptr;
}

std::set<std::string> Graph::ProcessNames() const {
  std::set<std::string> out;
  for (const auto& c : components) out.insert(ProcessOf(c));
  return out;
}

std::string Graph::ProcessOf(const ComponentConfig& c) const {
  if (!c.process.empty()) return c.process;
  if (processes.size() == 1) return processes.front().name;
  return "main";
}

const ProcessConfig* Graph::FindProcess(const std::string& n) const {
  for (const auto& p : processes)
    if (p.name == n) return &p;
  return nullptr;
}

bool Graph::PlacedOnHosts() const {
  return std::any_of(processes.begin(), processes.end(), [](const ProcessConfig& p) { return !p.host.empty(); });
}

const std::string& Graph::OriginOf(const std::string& key) const {
  // The longest prefix of key listed: key itself, then key without its last part, ..., then "".
  for (std::string k = key;;) {
    if (auto it = origins.find(k); it != origins.end()) return it->second;
    if (k.empty()) return file;
    const auto dot = k.rfind('.');
    k = dot == std::string::npos ? "" : k.substr(0, dot);
  }
}

SourceMark Graph::MarkOf(const std::string& key, const YAML::Node& node) const {
  const std::string& from = OriginOf(key);
  if (from.rfind("--set ", 0) == 0) return SourceMark{from, 0, 0};
  return SourceMark::Of(from, node);
}

std::string Graph::FolderOf(const std::string& key) const {
  const std::string& from = OriginOf(key);
  std::error_code ec;
  if (from.rfind("--set ", 0) == 0) return std::filesystem::current_path(ec).string();
  if (from == file) return folder;
  return std::filesystem::absolute(from, ec).parent_path().lexically_normal().string();
}

namespace {

// The graph's own scalars: graph, domain_id, clock, seed, plugins, logs.
void ReadGraphScalars(StrictYaml& r, const YAML::Node& root, Graph* g) {
  if (root["graph"] && r.String(root["graph"], "graph", &g->name) && !IsPartitionWord(g->name))
    r.Error(root["graph"], "graph", kGraphNameRule + (", got '" + g->name + "'"));
  if (root["domain_id"] && r.Get(root["domain_id"], "domain_id", &g->domain_id, "an integer") &&
      (g->domain_id < 0 || g->domain_id > 232))
    r.Error(root["domain_id"], "domain_id", "must be in 0..232 (DDS), got " + std::to_string(g->domain_id));
  if (root["clock"]) {
    g->clock_mark = r.Mark(root["clock"], "clock");
    std::string mode;
    if (r.String(root["clock"], "clock", &mode)) {
      if (mode == "wall") g->clock = ClockMode::kWall;
      else if (mode == "stepped") g->clock = ClockMode::kStepped;
      else r.Error(root["clock"], "clock", "must be wall or stepped, got '" + mode + "'");
    }
  }
  if (root["seed"]) r.Get(root["seed"], "seed", &g->seed, "a non-negative integer");
  if (const YAML::Node plugins = root["plugins"]) {
    const std::filesystem::path base = g->FolderOf("plugins");  // like every path of a graph file
    if (!plugins.IsSequence()) {
      r.Error(plugins, "plugins", "must be a list of paths");
    } else {
      for (const auto& p : plugins) {
        std::string s;
        if (!r.String(p, "plugins", &s)) continue;
        std::filesystem::path fp(s);
        g->plugins.push_back(fp.is_absolute() ? s : (base / fp).lexically_normal().string());
        g->plugin_marks.push_back(r.Mark(p, "plugins"));
      }
    }
  }
  if (root["logs"]) {
    std::string logs;
    const std::filesystem::path base = g->FolderOf("logs");
    if (r.String(root["logs"], "logs", &logs))
      g->logs = std::filesystem::path(logs).is_absolute() ? logs : (base / logs).lexically_normal().string();
  }
}

// `security.guests: {publish: [...], subscribe: [...]}`: topic names or patterns.
void ReadSecurityGuests(StrictYaml& r, const YAML::Node& node, Graph* g) {
  // Where a refusal sends the user: the publish list when there is one (the usual change).
  g->security.guests_mark = node["publish"] ? r.Mark(node["publish"], "security.guests.publish") : r.Mark(node, "security.guests");
  if (!r.Map(node, "security.guests", graph_keys::kSecurityGuests)) return;
  g->security.guests = true;
  for (const auto& [name, out] : {std::pair{"publish", &g->security.guest_publish}, {"subscribe", &g->security.guest_subscribe}}) {
    const std::string key = std::string("security.guests.") + name;
    const YAML::Node list = node[name];
    if (!list) continue;
    if (!list.IsSequence()) {
      r.Error(list, key, "must be a list of topics (names or patterns such as robot/*)");
      continue;
    }
    for (const auto& t : list) {
      std::string topic;
      if (r.String(t, key, &topic)) out->push_back(topic);
    }
  }
  if (g->security.guest_publish.empty() && g->security.guest_subscribe.empty())
    r.Error(node, "security.guests", "grants nothing: list the topics under publish: or subscribe: (or leave the section out)");
}

void ReadSecurity(StrictYaml& r, const YAML::Node& node, Graph* g) {
  if (!r.Map(node, "security", graph_keys::kSecurity)) return;
  if (!node["keystore"]) {
    r.Error(node, "security.keystore", "missing: the folder `dyad security init` made");
    return;
  }
  std::string keystore;
  g->security.mark = r.Mark(node["keystore"], "security.keystore");
  if (!r.String(node["keystore"], "security.keystore", &keystore)) return;
  if (keystore.empty()) {
    r.Error(node["keystore"], "security.keystore", "must name a folder");
    return;
  }
  const std::filesystem::path base = g->FolderOf("security.keystore");
  g->security.keystore = std::filesystem::path(keystore).is_absolute() ? keystore : (base / keystore).lexically_normal().string();
  if (const YAML::Node guests = node["guests"]) ReadSecurityGuests(r, guests, g);
}

// transport: tcp: each process listens on its tcp_port at its host's address; with processes on
// several hosts, each host's launcher on network.launcher_tcp_port (the launchers must meet to
// end every host's run when a required process fails for good: hosts/launcher_link.hpp).
void ListTcpListeners(StrictYaml& r, Graph* g) {
  NetworkConfig& net = g->network;
  std::map<std::string, std::string> taken;  // address:port -> who listens there
  auto listen = [&](const std::string& who, const std::string& address, int port, const SourceMark& mark,
                    const std::string& key) {
    const std::string at = address + ":" + std::to_string(port);
    if (auto [it, fresh] = taken.emplace(at, who); !fresh)
      r.Error(mark, key, "listens on " + at + ", as " + it->second + " does: give each its own port");
    else
      net.tcp_listeners[who] = at;
  };
  std::set<std::string> hosts;
  for (const auto& p : g->processes) {
    auto address = net.hosts.find(p.host);
    if (p.tcp_port == 0 || address == net.hosts.end()) {
      r.Error(p.mark, "processes." + p.name + ".tcp_port",
              "network.transport tcp needs each process's tcp_port and a host listed in network.hosts");
      continue;
    }
    hosts.insert(p.host);
    listen(p.name, address->second, p.tcp_port, p.mark, "processes." + p.name + ".tcp_port");
  }
  if (hosts.size() < 2) return;
  if (net.launcher_tcp_port == 0) {
    r.Error(net.mark, "network.launcher_tcp_port",
            "missing: with transport tcp and processes on several hosts, each host's launcher listens on it "
            "(else a required process that fails for good ends only its own host's run)");
    return;
  }
  if (net.launcher_tcp_port > 65535) return;  // reported with the network section
  for (const std::string& host : hosts)
    listen(LauncherParticipantName(host), net.hosts.at(host), net.launcher_tcp_port, net.mark,
           "network.launcher_tcp_port");
}

// `processes:`: each process's host, restart policy and port; then the rules across them.
void ReadProcesses(StrictYaml& r, const YAML::Node& procs, Graph* g) {
  if (!r.Map(procs, "processes", {})) return;
  for (const auto& kv : procs) {
    ProcessConfig p;
    p.name = kv.first.Scalar();
    const std::string key = "processes." + p.name;
    p.mark = r.Mark(kv.first, key);
    if (!IsPlaceName(p.name)) r.Error(kv.first, key, kPlaceNameRule + (", got '" + p.name + "'"));
    const YAML::Node spec = kv.second;
    if (!spec.IsNull() && r.Map(spec, key, graph_keys::kProcess)) {
      if (spec["host"] && r.String(spec["host"], key + ".host", &p.host) && !g->network.hosts.empty() &&
          !g->network.hosts.count(p.host))
        r.Error(spec["host"], key + ".host", "'" + p.host + "' is not one of network.hosts (" + Names(g->network.hosts) + ")");
      else if (spec["host"] && p.host.size() > kMaxPlaceName) r.Error(spec["host"], key + ".host", LongHostProblem(p.host));
      std::string policy;
      if (spec["restart"] && r.String(spec["restart"], key + ".restart", &policy)) {
        if (policy == "never") p.restart = RestartPolicy::kNever;
        else if (policy == "on-failure") p.restart = RestartPolicy::kOnFailure;
        else if (policy == "always") p.restart = RestartPolicy::kAlways;
        else r.Error(spec["restart"], key + ".restart", "must be never, on-failure or always, got '" + policy + "'");
      }
      if (spec["max_restarts"] && r.Get(spec["max_restarts"], key + ".max_restarts", &p.max_restarts, "an integer") &&
          p.max_restarts < 0)
        r.Error(spec["max_restarts"], key + ".max_restarts", "must be >= 0");
      if (spec["backoff_s"] && r.Get(spec["backoff_s"], key + ".backoff_s", &p.backoff_s, "a number") &&
          !(p.backoff_s >= 0.05 && p.backoff_s <= 60))
        r.Error(spec["backoff_s"], key + ".backoff_s", "must be in 0.05..60 (a shorter one restarts a crashing process in a tight loop)");
      if (spec["required"]) r.Get(spec["required"], key + ".required", &p.required, "true or false");
      if (spec["tcp_port"] && r.Get(spec["tcp_port"], key + ".tcp_port", &p.tcp_port, "an integer") &&
          (p.tcp_port < 1 || p.tcp_port > 65535))
        r.Error(spec["tcp_port"], key + ".tcp_port", "must be in 1..65535");
    }
    g->processes.push_back(p);
  }
  if (g->network.transport == NetTransport::kTcp) ListTcpListeners(r, g);
  // A process without a host would start on every host's launcher: a second copy of it.
  for (const auto& p : g->processes)
    if (g->PlacedOnHosts() && p.host.empty())
      r.Error(p.mark, "processes." + p.name + ".host", "missing: when one process names its host, every process must");
}


// A component left in the implicit process "main" of a graph placed on hosts would start on
// every host's launcher.
void CheckPlacement(StrictYaml& r, const Graph& g) {
  if (g.PlacedOnHosts() && g.processes.size() > 1) {
    for (const auto& c : g.components) {
      if (c.process.empty())
        r.Error(c.mark, "components." + c.name + ".process",
                "missing: the graph places its processes on hosts, so each component names its process");
    }
  }
}

// yaml_text for a graph with a chain or sets: the merged document, headed by what made it.
std::string GraphAsRun(const GraphDocument& doc, const std::string& file) {
  std::string header = "# the graph as run: " + file;
  for (size_t i = 0; i < doc.bases.size(); ++i) header += (i == 0 ? " extends " : ", ") + doc.bases[i];
  if (!doc.sets.empty()) header += " with";
  for (const std::string& set : doc.sets) header += " --set " + set;
  YAML::Emitter out;
  out << doc.root;
  return header + "\n" + out.c_str() + "\n";
}

// The --sets behind each component's params and the graph's own keys (for messages).
void NoteOverrides(Graph* g) {
  for (const auto& [key, from] : g->origins) {
    if (from.rfind("--set ", 0) != 0) continue;
    const std::string text = from.substr(6);
    if (key.rfind("components.", 0) != 0) {
      g->graph_overrides.push_back(text);
      continue;
    }
    const auto params = key.find(".params.");
    if (params == std::string::npos) continue;
    const std::string name = key.substr(11, params - 11);
    for (auto& c : g->components)
      if (c.name == name) c.overridden[key.substr(params + 8)] = text;
  }
}

// The document (the file, its `extends:` chain, the --sets), read into *g.
void ReadGraph(const std::string& yaml_text, const std::string& path, const std::vector<Override>& overrides, Graph* g,
               std::vector<Diagnostic>* diagnostics) {
  GraphDocument doc = ReadGraphDocument(yaml_text, path, diagnostics);
  if (!doc.root.IsMap()) return;  // unreadable: said why; a --set has nothing to be checked against
  ApplySets(overrides, &doc, diagnostics);
  g->origins = doc.origins;
  const YAML::Node root = doc.root;
  // Each problem at the file (or --set) that wrote its key.
  StrictYaml r([g](const std::string& key, const YAML::Node& node) { return g->MarkOf(key, node); }, diagnostics);
  r.Map(root, "", graph_keys::kTopLevel);
  ReadGraphScalars(r, root, g);
  if (const YAML::Node network = root["network"]) ReadNetwork(r, network, &g->network);
  if (const YAML::Node procs = root["processes"]) ReadProcesses(r, procs, g);
  if (const YAML::Node security = root["security"]) ReadSecurity(r, security, g);
  ResolveScope(r, root["network"], g);
  if (const YAML::Node topics = root["topics"]) ReadTopics(r, topics, g);
  if (const YAML::Node comps = root["components"]) ReadComponents(r, comps, g);
  else r.Error(SourceMark{path, 1, 1}, "components", "missing: a graph needs at least one component");
  CheckPlacement(r, *g);
  NoteOverrides(g);
  if (!doc.bases.empty() || !doc.sets.empty()) g->yaml_text = GraphAsRun(doc, path);
}

}  // namespace

Graph ParseGraph(const std::string& yaml_text, const std::string& path, const std::vector<Override>& overrides,
                 std::vector<Diagnostic>* diagnostics) {
  Graph g;
  g.file = path;
  {
    std::error_code ec;
    const std::filesystem::path cwd = std::filesystem::current_path(ec);
    g.folder = (path.empty() ? cwd : std::filesystem::absolute(path, ec).parent_path()).lexically_normal().string();
  }
  g.yaml_text = yaml_text;
  // Every reader above turns what it finds into diagnostics; yaml-cpp throws where a node is used
  // as what it is not (a key of a scalar, the type of an absent key). Should a path still do so,
  // that is a diagnostic at the graph file too, never an exception out of the loader (the CLI
  // would die with std::terminate, exit 134).
  try {
    ReadGraph(yaml_text, path, overrides, &g, diagnostics);
  } catch (const YAML::Exception& e) {
    diagnostics->push_back({SourceMark{path, e.mark.is_null() ? 0 : e.mark.line + 1, e.mark.is_null() ? 0 : e.mark.column + 1},
                            "", "cannot read the graph: " + e.msg});
  }
  return g;
}

std::string LocalScopeNote(const NetworkConfig& network, bool watcher) {
  if (network.scope != NetScope::kLocal) return "";
  if (watcher)
    return "this watcher is local (network.scope: local, as a graph that names no other machine is, and a watcher "
           "without --graph): it reaches this machine only and sees no graph of scope lan; to watch one, give its "
           "--graph (a graph on another machine needs `network.scope: lan` or its hosts named)";
  return "the graph is local (network.scope: local, the default of a graph that names no other machine): it reaches "
         "this machine only, so a process on another machine is never seen; to run it on several machines, set "
         "`network.scope: lan` (or --set network.scope=lan) or name the hosts (network.hosts, and each process's host:)";
}

Graph LoadGraph(const std::string& path, const std::vector<Override>& overrides, std::vector<Diagnostic>* diagnostics) {
  std::ifstream in(path);
  std::error_code ec;
  if (!in || std::filesystem::is_directory(path, ec)) {
    diagnostics->push_back({SourceMark{path, 0, 0}, "", in ? "is a folder, not a graph file" : "cannot open graph file"});
    Graph g;
    g.file = path;
    return g;
  }
  std::stringstream ss;
  ss << in.rdbuf();
  return ParseGraph(ss.str(), path, overrides, diagnostics);
}

}  // namespace dyad
