// dyad/graph.hpp — an experiment graph as read from YAML, before and after validation.
//
// File format (every key is checked; unknown keys are errors):
//
//   extends: demo.yaml          # optional: this file's keys merged over that graph's (maps key by
//                               # key; `key: !reset` removes, `key: !override {...}` replaces a map)
//   graph: demo                 # name, used in DDS participant names
//   domain_id: 0                # DDS domain, 0..232
//   clock: wall                 # wall | stepped
//   seed: 1                     # stepped-mode determinism and component seeds
//   plugins: [build/plugins]    # extra plugin files or folders, relative to this file
//   logs: ../out/logs           # the launcher writes each process's output to <logs>/<process>.log
//   network:                    # optional: how processes find each other (docs/distributed.md)
//     discovery: multicast      # multicast (default) | peers | server
//     hosts: {lab: 10.0.0.1, robot-pc: 10.0.0.2}   # host name -> address
//     peers: [10.0.0.9:7412]    # discovery: peers (default: every address in hosts)
//     server: lab:11811         # discovery: server; a host of `hosts` (its launcher starts the
//                               # server) or an address (started by you: `dyad discovery-server`)
//     transport: shm+udp        # shm+udp (default) | udp | tcp (each process: tcp_port)
//     interfaces: [eth0]        # only these interfaces (names or addresses); default: all
//     lease_s: 5                # a silent process is declared gone after this long
//     start_timeout_s: 30       # how long a process waits for the others to start together
//     max_clock_offset_ms: 5    # warn when another process's clock is further off than this
//   security:                   # optional: DDS Security for every participant (dyad/security.hpp)
//     keystore: keys/demo       # made by `dyad security init keys/demo --graph THIS_FILE`
//     guests:                   # optional: what the lab's tools may do in the secured graph, with
//       publish: [human/input]  #   the identity `guest` init issues (dyad pub, dyad bag play);
//       subscribe: []           #   topic names or patterns (fnmatch, as DDS Security matches them)
//   processes:                  # optional; default: one process "main"
//     main: {}
//     robot: {host: robot-pc}   # host: where `dyad run` without --process starts it (default: here;
//                               # when one process names its host, every process must)
//     mind: {restart: on-failure, max_restarts: 3, backoff_s: 0.5, required: true, tcp_port: 7600}
//                               # supervision: never (default) | on-failure | always
//   topics:                     # optional per topic: type and QoS
//     human/input: {type: HumanInput, reliability: reliable, depth: 1, deadline_ms: 200, liveliness_ms: 500}
//   components:
//     human:
//       type: synthetic_human   # a registered component type (`dyad types`)
//       rate_hz: 10             # periodic; or `trigger: <input name>` to step on arrival
//       process: main
//       params: {noise: 0.5}
//       inputs: {robot: robot/state}     # port name: topic
//       outputs: {input: human/input}
//
// LoadGraph reads the file (and the files it extends) and applies `--set` overrides;
// ValidateGraph (validate.hpp) checks it against the component types. Both return every
// problem found, each "file:line:col: key: message".
#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "dyad/diagnostic.hpp"

namespace dyad {

enum class Reliability { kReliable, kBestEffort };
enum class ClockMode { kWall, kStepped };

struct TopicConfig {
  std::string name;
  std::string type;  // as written: "HumanInput" or "dyad::msg::HumanInput"; empty: from ports
  Reliability reliability = Reliability::kReliable;
  int depth = 1;             // KEEP_LAST history depth
  double deadline_ms = 0;    // 0: none
  double liveliness_ms = 0;  // 0: the network's lease_s; else a writer silent this long is not alive
  // A ROS 2 topic (dyad/ros2_names.hpp): its fully qualified ROS 2 name; empty for a dyad topic.
  // `qos:` names its ROS 2 QoS profile (default "default"), which sets reliability and depth
  // unless the entry sets them too.
  std::string ros2;
  std::string ros2_qos;
  SourceMark mark;
  SourceMark type_mark;
  SourceMark ros2_mark;
};

enum class Discovery { kMulticast, kPeers, kServer };
// Who can reach the graph's participants. kLocal: this machine only (loopback and shared memory;
// discovery by unicast on 127.0.0.1): the default of a graph that points at no other machine,
// and of a watcher without --graph. kLan: the network the `network:` section describes.
enum class NetScope { kLocal, kLan };
enum class NetTransport { kShmUdp, kUdp, kTcp };

// The DDS participant name of a host's launcher (its link to the other hosts' launchers).
inline std::string LauncherParticipantName(const std::string& host) { return "dyad/launcher/" + host; }

// The `network:` section, mapped onto Fast DDS participant QoS by the runtime.
struct NetworkConfig {
  // `network.scope`; when not given: kLan if the graph points at another machine (processes on
  // hosts, network.hosts, peers, server, interfaces, transport tcp, discovery other than
  // multicast), else kLocal.
  NetScope scope = NetScope::kLocal;
  Discovery discovery = Discovery::kMulticast;
  std::map<std::string, std::string> hosts;  // host name -> address (IPv4 or DNS name)
  std::vector<std::string> peers;            // "address" or "address:port" (port 0: well-known ports)
  std::string server;                        // "host-or-address:port" as written
  std::string server_address;                // resolved through `hosts`
  int server_port = 0;
  std::string server_host;                   // the host of `hosts` that runs the server; empty: external
  NetTransport transport = NetTransport::kShmUdp;
  // transport: tcp: every listener, "address:port": each process's (network.hosts[host]:tcp_port)
  // and, with processes on several hosts, each host's launcher's (LauncherParticipantName(host)
  // -> network.hosts[host]:launcher_tcp_port). Each pair connects once: the later name dials.
  std::map<std::string, std::string> tcp_listeners;  // process or launcher -> address:port
  int launcher_tcp_port = 0;
  std::vector<std::string> interfaces;
  double lease_s = 5;
  double start_timeout_s = 30;
  double max_clock_offset_ms = 5;  // a peer's measured clock offset beyond it is warned about
  SourceMark mark;
};

// The `security:` section: DDS Security for every participant (dyad/security.hpp).
struct SecurityConfig {
  std::string keystore;  // resolved against the file's folder; empty: no security
  SourceMark mark;       // of `security.keystore`
  // `security.guests`: the grant of the identity `guest` (dyad/security.hpp: kGuestIdentity).
  bool guests = false;   // the section is there (then init issues the guest identity)
  std::vector<std::string> guest_publish, guest_subscribe;  // topic names or fnmatch patterns
  SourceMark guests_mark;  // of `security.guests.publish` (else of `security.guests`)
  bool enabled() const { return !keystore.empty(); }
};

enum class RestartPolicy { kNever, kOnFailure, kAlways };

struct ProcessConfig {
  std::string name;
  std::string host;  // empty: this machine
  // Supervision by the launcher (run.hpp): restart after an exit (on-failure: a non-zero one),
  // up to max_restarts times, waiting backoff_s, doubled after each restart (at most 10 s).
  RestartPolicy restart = RestartPolicy::kNever;
  int max_restarts = 3;
  double backoff_s = 0.5;
  // A required process that fails for good ends the experiment; another one is left out.
  bool required = true;
  int tcp_port = 0;  // network.transport: tcp: the port this process listens on
  SourceMark mark;
};

struct PortBinding {
  std::string port;
  std::string topic;
  SourceMark mark;
};

struct ComponentConfig {
  std::string name;
  std::string type;
  std::string process;     // empty: the graph's only/default process
  double rate_hz = 0;      // > 0: periodic
  std::string trigger;     // input name: step when it receives
  YAML::Node params;       // map as written (with overrides applied)
  std::map<std::string, std::string> overridden;  // param -> the --set text that set it
  std::vector<PortBinding> inputs, outputs;
  SourceMark mark, type_mark, rate_mark, trigger_mark, process_mark, params_mark;
};

struct Graph {
  std::string file;  // path as given
  // The folder relative paths of the file are relative to: the file's, made absolute (the
  // working folder for a graph without a file name).
  std::string folder;
  std::string name = "dyad";
  // This run's id (`dyad run --run-id`, or the launcher's choice; not in the file): with the
  // name, the DDS partition that isolates the run from others on the domain.
  std::string run;
  int domain_id = 0;
  ClockMode clock = ClockMode::kWall;
  uint64_t seed = 1;
  std::vector<std::string> plugins;  // resolved against the file's folder
  std::string logs;                  // the launcher's per-process log folder, resolved; "": none
  std::vector<SourceMark> plugin_marks;  // where each of `plugins` is written
  NetworkConfig network;
  SecurityConfig security;
  std::vector<ProcessConfig> processes;
  std::vector<TopicConfig> topics;
  std::vector<ComponentConfig> components;
  // The file as read; with `extends:` or --set overrides, the graph as run (the merged
  // document re-emitted under a comment naming the files and the sets; relative paths as each
  // file wrote them). Recorders store it as metadata.
  std::string yaml_text;
  // Where each part of the graph was written: key path ("components.robot.params.model") -> a
  // file of the `extends:` chain, or "--set TEXT". The longest listed prefix of a key holds
  // ("" for all of it); a key under none was written in `file`.
  std::map<std::string, std::string> origins;
  std::vector<std::string> graph_overrides;  // "clock=wall" etc.: --set of the graph's own scalars
  SourceMark clock_mark;                     // where `clock:` was set (file line, or the --set); empty: default

  const ComponentConfig* FindComponent(const std::string& name) const;
  const TopicConfig* FindTopic(const std::string& name) const;
  // The process a component runs in ("main" when the graph lists none).
  std::string ProcessOf(const ComponentConfig& c) const;
  // Every process that runs a component.
  std::set<std::string> ProcessNames() const;
  // The process of that name under `processes:`; null when the file does not list it (it then
  // has the defaults of ProcessConfig).
  const ProcessConfig* FindProcess(const std::string& name) const;
  // Whether the graph places its processes on hosts (then every process names one).
  bool PlacedOnHosts() const;
  // The file (or "--set TEXT") that wrote `key` (see origins).
  const std::string& OriginOf(const std::string& key) const;
  // Where `node`, the value at `key`, was written: its file's line, or the --set.
  SourceMark MarkOf(const std::string& key, const YAML::Node& node) const;
  // The folder a relative path at `key` is relative to: its file's folder, absolute; the
  // working folder for a --set.
  std::string FolderOf(const std::string& key) const;
};

// `--set KEY=VALUE`: VALUE (parsed as YAML) written at KEY, as if the file said it:
// `NAME.PARAM=V` a component's parameter, `NAME.type=T` (rate_hz, trigger, process) its own keys,
// `NAME.inputs.PORT=TOPIC`, `clock=wall` (seed, domain_id, graph, logs, plugins) the graph's,
// `network.KEY=V`, `security.keystore=DIR`, `processes.NAME.KEY=V`, `topics.TOPIC.KEY=V` (graph_document.hpp).
struct Override {
  std::string text;  // as given, for messages
};

// Parses `path`. Structural problems (bad YAML, unknown keys, wrong scalar types, duplicates)
// are appended to *diagnostics; the returned graph holds what could be read.
Graph LoadGraph(const std::string& path, const std::vector<Override>& overrides,
                std::vector<Diagnostic>* diagnostics);
// Same, from text (tests); `path` is used in messages and to resolve plugin paths.
Graph ParseGraph(const std::string& yaml_text, const std::string& path, const std::vector<Override>& overrides,
                 std::vector<Diagnostic>* diagnostics);

}  // namespace dyad
