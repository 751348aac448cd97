// The graph's `network:` section: read, checked (each problem at its line, or at the --set that
// caused it) and mapped onto Fast DDS participant QoS.
#include <gtest/gtest.h>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/rtps/transport/TCPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include <dyad/graph.hpp>

#include "dds/network_qos.hpp"
#include "graph/host_port.hpp"

namespace dyad {
namespace {

const char* kSplit =
    "graph: split\n"                              // 1
    "network:\n"                                  // 2
    "  discovery: peers\n"                        // 3
    "  hosts: {lab: 10.77.0.1, mind: 10.77.0.2}\n"  // 4
    "  peers: [10.77.0.9:7412]\n"                 // 5
    "  server: lab:11811\n"                       // 6
    "  transport: udp\n"                          // 7
    "  interfaces: [veth0]\n"                     // 8
    "  lease_s: 3\n"                              // 9
    "  start_timeout_s: 12\n"                     // 10
    "processes:\n"                                // 11
    "  a: {host: lab}\n"                          // 12
    "  b: {host: mind}\n"                         // 13
    "components:\n"                               // 14
    "  src: {type: counter_source, rate_hz: 10, process: a, outputs: {out: c}}\n"
    "  sink: {type: counter_sink, trigger: in, process: b, inputs: {in: c}}\n";

Graph Parse(const std::string& yaml, std::vector<Diagnostic>* diags, const std::vector<std::string>& sets = {}) {
  std::vector<Override> overrides;
  for (const auto& s : sets) overrides.push_back({s});
  return ParseGraph(yaml, "g.yaml", overrides, diags);
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

// kSplit over TCP: each process's port, and the launchers' (its processes are on two hosts);
// launcher_tcp_port takes start_timeout_s's line, so the lines below it keep their numbers.
std::string Tcp(const std::string& yaml) {
  return Replace(Replace(Replace(Replace(yaml, "transport: udp", "transport: tcp"), "  start_timeout_s: 12\n",
                                 "  launcher_tcp_port: 7600\n"),
                         "a: {host: lab}", "a: {host: lab, tcp_port: 7601}"),
                 "b: {host: mind}", "b: {host: mind, tcp_port: 7602}");
}

TEST(NetworkConfig, ReadsEveryKey) {
  std::vector<Diagnostic> diags;
  const Graph g = Parse(kSplit, &diags);
  ASSERT_TRUE(diags.empty()) << diags[0].ToString();
  const NetworkConfig& n = g.network;
  EXPECT_EQ(n.discovery, Discovery::kPeers);
  EXPECT_EQ(n.hosts.at("mind"), "10.77.0.2");
  EXPECT_EQ(n.peers, std::vector<std::string>{"10.77.0.9:7412"});
  EXPECT_EQ(n.server_host, "lab");
  EXPECT_EQ(n.server_address, "10.77.0.1");
  EXPECT_EQ(n.server_port, 11811);
  EXPECT_EQ(n.transport, NetTransport::kUdp);
  EXPECT_EQ(n.interfaces, std::vector<std::string>{"veth0"});
  EXPECT_EQ(n.lease_s, 3);
  EXPECT_EQ(n.start_timeout_s, 12);
}

TEST(NetworkConfig, DefaultsToMulticastOverSharedMemoryAndUdp) {
  std::vector<Diagnostic> diags;
  const Graph g = Parse("components:\n  src: {type: counter_source, rate_hz: 10}\n", &diags);
  ASSERT_TRUE(diags.empty());
  EXPECT_EQ(g.network.discovery, Discovery::kMulticast);
  EXPECT_EQ(g.network.transport, NetTransport::kShmUdp);
  EXPECT_EQ(g.network.scope, NetScope::kLocal);  // names no other machine: this machine only
}

// network.scope: local unless the graph points at another machine, whichever key does; lan on request.
TEST(NetworkConfig, ScopeIsLocalUnlessTheGraphPointsAtAnotherMachine) {
  const std::string plain = "components:\n  src: {type: counter_source, rate_hz: 10}\n";
  for (const char* set : {"network.hosts.lab=10.0.0.1", "network.peers=[10.0.0.2]", "network.server=10.0.0.1:11811",
                                 "network.interfaces=[10.0.0.1]", "network.discovery=peers", "network.scope=lan"}) {
    std::vector<Diagnostic> diags;
    const Graph g = Parse(plain, &diags, {set});
    EXPECT_EQ(g.network.scope, NetScope::kLan) << set;
  }
  std::vector<Diagnostic> diags;
  EXPECT_EQ(Parse(kSplit, &diags).network.scope, NetScope::kLan);
  EXPECT_EQ(Parse(plain, &diags, {"network.scope=local"}).network.scope, NetScope::kLocal);
  EXPECT_TRUE(diags.empty()) << diags[0].ToString();
}

struct Bad {
  const char* name;
  std::string yaml;
  const char* mark;
  const char* key;
  const char* why;
};

class BadNetwork : public ::testing::TestWithParam<Bad> {};

TEST_P(BadNetwork, IsRejectedAtItsLine) {
  std::vector<Diagnostic> diags;
  Parse(GetParam().yaml, &diags);
  std::string all;
  for (const auto& d : diags) all += d.ToString() + "\n";
  ASSERT_EQ(diags.size(), 1u) << all;
  EXPECT_EQ(diags[0].mark.ToString().rfind(GetParam().mark, 0), 0u) << diags[0].ToString();
  EXPECT_EQ(diags[0].key, GetParam().key) << diags[0].ToString();
  EXPECT_NE(diags[0].message.find(GetParam().why), std::string::npos) << diags[0].ToString();
}

INSTANTIATE_TEST_SUITE_P(
    Table, BadNetwork,
    ::testing::Values(
        Bad{"UnknownKey", Replace(kSplit, "  lease_s: 3\n", "  lease: 3\n"), "g.yaml:9:3", "network.lease", "unknown key"},
        Bad{"BadDiscovery", Replace(kSplit, "discovery: peers", "discovery: gossip"), "g.yaml:3:14", "network.discovery",
            "multicast, peers or server"},
        Bad{"BadTransport", Replace(kSplit, "transport: udp", "transport: quic"), "g.yaml:7:14", "network.transport",
            "shm+udp, udp or tcp"},
        Bad{"ServerWithoutPort", Replace(kSplit, "server: lab:11811", "server: lab"), "g.yaml:6:11", "network.server",
            "HOST:PORT"},
        Bad{"ServerPortTooBig", Replace(kSplit, "server: lab:11811", "server: lab:70000"), "g.yaml:6:11", "network.server",
            "HOST:PORT"},
        Bad{"PeerWithBadPort", Replace(kSplit, "10.77.0.9:7412", "10.77.0.9:x"), "g.yaml:5:10", "network.peers",
            "address:port"},
        Bad{"PeersWithNowhereToAnnounce",
            Replace(Replace(Replace(Replace(kSplit, "  hosts: {lab: 10.77.0.1, mind: 10.77.0.2}\n", ""), "  peers: [10.77.0.9:7412]\n", ""),
                            "  server: lab:11811\n", ""),
                    "processes:\n  a: {host: lab}\n  b: {host: mind}\n", "processes:\n  a: {}\n  b: {}\n"),
            "g.yaml:3:14", "network.discovery", "needs network.peers or network.hosts"},
        Bad{"ShortLease", Replace(kSplit, "lease_s: 3", "lease_s: 0.2"), "g.yaml:9:12", "network.lease_s", ">= 1"},
        Bad{"HostNotInHosts", Replace(kSplit, "b: {host: mind}", "b: {host: mnid}"), "g.yaml:13:13", "processes.b.host",
            "'mnid' is not one of network.hosts (lab, mind)"},
        Bad{"ProcessWithoutHostBesideOneWithHost", Replace(kSplit, "b: {host: mind}", "b: {}"), "g.yaml:13:3",
            "processes.b.host", "every process must"},
        Bad{"ComponentWithoutProcessInAGraphOnHosts", Replace(kSplit, "process: b, ", ""), "g.yaml:16:3",
            "components.sink.process", "each component names its process"},
        Bad{"TcpWithoutPeers", Replace(Tcp(kSplit), "discovery: peers", "discovery: multicast"), "g.yaml:7:14",
            "network.transport", "tcp: needs discovery: peers"},
        Bad{"TcpOnTwoHostsWithoutALauncherPort", Replace(Tcp(kSplit), "  launcher_tcp_port: 7600\n", ""), "g.yaml:3:3",
            "network.launcher_tcp_port", "each host's launcher listens on it"},
        Bad{"TcpLauncherPortTakenByAProcess", Replace(Tcp(kSplit), "launcher_tcp_port: 7600", "launcher_tcp_port: 7602"),
            "g.yaml:3:3", "network.launcher_tcp_port", "listens on 10.77.0.2:7602, as b does"},
        Bad{"TcpLauncherPortOutOfRange", Replace(Tcp(kSplit), "launcher_tcp_port: 7600", "launcher_tcp_port: 70000"),
            "g.yaml:10:22", "network.launcher_tcp_port", "1..65535"},
        Bad{"TcpWithoutAPort", Replace(Replace(kSplit, "transport: udp", "transport: tcp"), "a: {host: lab}", "a: {host: lab, tcp_port: 7601}"),
            "g.yaml:13:3", "processes.b.tcp_port", "needs each process's tcp_port"},
        Bad{"ProcessNameThatIsAPath", Replace(kSplit, "a: {host: lab}", "../a: {host: lab}"), "g.yaml:12:3", "processes.../a",
            "A-Z a-z 0-9 _ -, not starting with - (it names a log file and a DDS participant), got '../a'"},
        Bad{"HostNameWithASlash",
            Replace(Replace(kSplit, "mind: 10.77.0.2", "mi/nd: 10.77.0.2"), "b: {host: mind}", "b: {host: mi/nd}"),
            "g.yaml:4:27", "network.hosts.mi/nd", "got 'mi/nd'"},
        Bad{"LocalScopeOnHosts", Replace(kSplit, "  lease_s: 3\n", "  scope: local\n"), "g.yaml:9:10", "network.scope",
            "local: this machine only, but the graph points at others (processes on hosts)"},
        Bad{"UnknownScope", Replace(kSplit, "  lease_s: 3\n", "  scope: world\n"), "g.yaml:9:10", "network.scope",
            "must be local (this machine only) or lan, got 'world'"},
        Bad{"BackoffTooShort", Replace(kSplit, "a: {host: lab}", "a: {host: lab, restart: always, backoff_s: 0}"), "g.yaml:12:46",
            "processes.a.backoff_s", "0.05..60"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(NetworkConfig, ASetOverridesAKeyAndItsProblemNamesTheSet) {
  std::vector<Diagnostic> diags;
  Graph g = Parse(kSplit, &diags, {"network.discovery=server", "network.start_timeout_s=5"});
  ASSERT_TRUE(diags.empty()) << diags[0].ToString();
  EXPECT_EQ(g.network.discovery, Discovery::kServer);
  EXPECT_EQ(g.network.start_timeout_s, 5);
  EXPECT_NE(g.yaml_text.find("--set network.discovery=server"), std::string::npos) << g.yaml_text;  // recorded as run

  diags.clear();
  Parse(kSplit, &diags, {"network.discovery=gossip"});
  ASSERT_EQ(diags.size(), 1u);
  EXPECT_EQ(diags[0].mark.ToString(), "--set network.discovery=gossip");
  EXPECT_EQ(diags[0].key, "network.discovery");

  diags.clear();
  Parse(kSplit, &diags, {"network.lease_s"});
  ASSERT_EQ(diags.size(), 1u);
  EXPECT_NE(diags[0].message.find("network.KEY=VALUE"), std::string::npos) << diags[0].ToString();

  // A key inside a key: one host's address (a lab PC that got a new one).
  diags.clear();
  g = Parse(kSplit, &diags, {"network.hosts.lab=10.9.9.9"});
  ASSERT_TRUE(diags.empty()) << diags[0].ToString();
  EXPECT_EQ(g.network.hosts.at("lab"), "10.9.9.9");
  EXPECT_EQ(g.network.hosts.size(), 2u);
}

// `--set processes.NAME.KEY=VALUE` changes one process's supervision (a run without restarts, say),
// checked like the file's own; its problems name the --set.
TEST(NetworkConfig, ASetOverridesAProcesssKeyAndItsProblemNamesTheSet) {
  std::vector<Diagnostic> diags;
  Graph g = Parse(Replace(kSplit, "a: {host: lab}", "a: {host: lab, restart: on-failure}"), &diags,
                  {"processes.a.restart=never", "processes.b.max_restarts=7"});
  ASSERT_TRUE(diags.empty()) << diags[0].ToString();
  ASSERT_EQ(g.processes.size(), 2u);
  for (const auto& pc : g.processes) {
    if (pc.name == "a") {
      EXPECT_EQ(pc.restart, RestartPolicy::kNever);
    } else {
      EXPECT_EQ(pc.max_restarts, 7);
    }
  }
  EXPECT_NE(g.yaml_text.find("--set processes.a.restart=never"), std::string::npos) << g.yaml_text;

  diags.clear();
  Parse(kSplit, &diags, {"processes.a.restart=sometimes"});
  ASSERT_EQ(diags.size(), 1u);
  EXPECT_EQ(diags[0].mark.ToString(), "--set processes.a.restart=sometimes");
  EXPECT_EQ(diags[0].key, "processes.a.restart");

  struct Case {
    const char* set;
    const char* says;
  };
  for (const Case& c : {Case{"processes.a=never", "expected processes.NAME.KEY=VALUE"},
                        Case{"processes.a.restart.x=1", "expected processes.NAME.KEY=VALUE"},
                        Case{"processes.zz.restart=never", "no such process"}}) {
    diags.clear();
    Parse(kSplit, &diags, {c.set});
    ASSERT_EQ(diags.size(), 1u) << c.set;
    EXPECT_NE(diags[0].message.find(c.says), std::string::npos) << c.set << ": " << diags[0].ToString();
    EXPECT_EQ(diags[0].mark.ToString(), std::string("--set ") + c.set);
  }
  diags.clear();  // a process that is not a mapping: the file's error and the --set's, no YAML exception
  Parse(Replace(kSplit, "a: {host: lab}", "a: 3"), &diags, {"processes.a.restart=never"});
  std::string all;
  for (const auto& d : diags) all += d.ToString() + "\n";
  ASSERT_GE(diags.size(), 2u) << all;  // and what follows from a (no host)
  EXPECT_NE(all.find("g.yaml:12:6: processes.a: must be a mapping"), std::string::npos) << all;
  EXPECT_NE(all.find("--set processes.a.restart=never: processes.a.restart: cannot set 'restart' inside processes.a, which "
                     "is a scalar"),
            std::string::npos)
      << all;
}

// TCP: each process listens on its port at its host's address, each host's launcher on
// launcher_tcp_port, and each connects only to the listeners named before it (one connection
// per pair); a watcher connects to all.
TEST(NetworkQos, TcpListensOnTheProcesssPortAndConnectsToTheEarlierProcesses) {
  std::vector<Diagnostic> diags;
  const Graph g = Parse(Tcp(kSplit), &diags);
  ASSERT_TRUE(diags.empty()) << diags[0].ToString();
  EXPECT_EQ(g.network.tcp_listeners.at("b"), "10.77.0.2:7602");
  auto peers_of = [&](const std::string& process, std::vector<uint16_t>* listening) {
    eprosima::fastdds::dds::DomainParticipantQos qos;
    EXPECT_TRUE(ApplyNetwork(g.network, process.empty(), &qos, process).ok());
    auto tcp = std::dynamic_pointer_cast<eprosima::fastdds::rtps::TCPv4TransportDescriptor>(qos.transport().user_transports.at(0));
    EXPECT_NE(tcp, nullptr);
    if (tcp) *listening = tcp->listening_ports;
    std::vector<std::string> peers;
    for (const auto& l : qos.wire_protocol().builtin.initialPeersList)
      peers.push_back(eprosima::fastrtps::rtps::IPLocator::ip_to_string(l) + ":" +
                      std::to_string(eprosima::fastrtps::rtps::IPLocator::getPhysicalPort(l)));
    return peers;
  };
  std::vector<uint16_t> listening;
  EXPECT_TRUE(peers_of("a", &listening).empty());
  EXPECT_EQ(listening, std::vector<uint16_t>{7601});
  EXPECT_EQ(peers_of("b", &listening), std::vector<std::string>{"10.77.0.1:7601"});
  EXPECT_EQ(listening, std::vector<uint16_t>{7602});
  EXPECT_EQ(peers_of(LauncherParticipantName("lab"), &listening), (std::vector<std::string>{"10.77.0.1:7601", "10.77.0.2:7602"}));
  EXPECT_EQ(listening, std::vector<uint16_t>{7600});
  EXPECT_EQ(peers_of(LauncherParticipantName("mind"), &listening),
            (std::vector<std::string>{"10.77.0.1:7601", "10.77.0.2:7602", "10.77.0.1:7600"}));
  EXPECT_EQ(listening, std::vector<uint16_t>{7600});
  EXPECT_EQ(peers_of("", &listening),
            (std::vector<std::string>{"10.77.0.1:7601", "10.77.0.2:7602", "10.77.0.1:7600", "10.77.0.2:7600"}));
  EXPECT_TRUE(listening.empty());
}

// The QoS a participant gets from each discovery mode.
eprosima::fastdds::dds::DomainParticipantQos QosOf(const std::string& sets) {
  std::vector<Diagnostic> diags;
  const Graph g = Parse(kSplit, &diags, {sets});
  EXPECT_TRUE(diags.empty());
  eprosima::fastdds::dds::DomainParticipantQos qos;
  Status s = ApplyNetwork(g.network, false, &qos);
  EXPECT_TRUE(s.ok()) << s.ToString();
  return qos;
}

TEST(NetworkQos, PeersTurnMulticastOffAndListEveryHostAndPeer) {
  const auto qos = QosOf("network.discovery=peers");
  const auto& b = qos.wire_protocol().builtin;
  ASSERT_EQ(b.metatrafficUnicastLocatorList.size(), 1u);  // its presence keeps multicast off
  EXPECT_TRUE(b.metatrafficMulticastLocatorList.empty());
  std::vector<std::string> peers;
  for (const auto& l : b.initialPeersList) peers.push_back(eprosima::fastrtps::rtps::IPLocator::ip_to_string(l) + ":" + std::to_string(l.port));
  EXPECT_EQ(peers, (std::vector<std::string>{"10.77.0.1:0", "10.77.0.2:0", "10.77.0.9:7412"}));
  EXPECT_EQ(b.discovery_config.leaseDuration, eprosima::fastrtps::Duration_t(3.0));
  EXPECT_EQ(b.discovery_config.leaseDuration_announcementperiod, eprosima::fastrtps::Duration_t(0.75));
  // transport: udp: no shared memory; the allow-list and the wider peer range reach UDP.
  ASSERT_EQ(qos.transport().user_transports.size(), 1u);
  EXPECT_FALSE(qos.transport().use_builtin_transports);
  auto udp = std::dynamic_pointer_cast<eprosima::fastdds::rtps::UDPv4TransportDescriptor>(qos.transport().user_transports[0]);
  ASSERT_NE(udp, nullptr);
  EXPECT_EQ(udp->interfaceWhiteList, std::vector<std::string>{"veth0"});
  EXPECT_EQ(udp->maxInitialPeersRange, static_cast<uint32_t>(kPeerParticipants));
}

// scope local (a graph naming no other machine): loopback only, shared memory, no multicast,
// discovery by unicast to 127.0.0.1.
TEST(NetworkQos, LocalScopeBindsToLoopbackAndSendsNoMulticast) {
  std::vector<Diagnostic> diags;
  const Graph g = Parse("components:\n  src: {type: counter_source, rate_hz: 10}\n", &diags);
  ASSERT_TRUE(diags.empty());
  eprosima::fastdds::dds::DomainParticipantQos qos;
  ASSERT_TRUE(ApplyNetwork(g.network, false, &qos).ok());
  const auto& b = qos.wire_protocol().builtin;
  ASSERT_EQ(b.metatrafficUnicastLocatorList.size(), 1u);  // keeps Fast DDS from adding the multicast one
  EXPECT_TRUE(b.metatrafficMulticastLocatorList.empty());
  ASSERT_EQ(b.initialPeersList.size(), 1u);
  EXPECT_EQ(eprosima::fastrtps::rtps::IPLocator::ip_to_string(*b.initialPeersList.begin()), "127.0.0.1");
  ASSERT_EQ(qos.transport().user_transports.size(), 2u);
  EXPECT_NE(std::dynamic_pointer_cast<eprosima::fastdds::rtps::SharedMemTransportDescriptor>(qos.transport().user_transports[0]), nullptr);
  auto udp = std::dynamic_pointer_cast<eprosima::fastdds::rtps::UDPv4TransportDescriptor>(qos.transport().user_transports[1]);
  ASSERT_NE(udp, nullptr);
  EXPECT_EQ(udp->interfaceWhiteList, std::vector<std::string>{"127.0.0.1"});
  EXPECT_EQ(udp->maxInitialPeersRange, static_cast<uint32_t>(kLocalParticipants));
}

// Fast DDS 2.9 whitelists by address only: an interface's name becomes its addresses.
TEST(NetworkQos, AnInterfaceNameBecomesItsAddress) {
  const auto qos = QosOf("network.interfaces=[lo, 10.77.0.1, no-such-interface]");
  auto udp = std::dynamic_pointer_cast<eprosima::fastdds::rtps::UDPv4TransportDescriptor>(qos.transport().user_transports.at(0));
  ASSERT_NE(udp, nullptr);
  EXPECT_EQ(udp->interfaceWhiteList, (std::vector<std::string>{"127.0.0.1", "10.77.0.1", "no-such-interface"}));
}

TEST(NetworkQos, ServerMakesAClientOfTheNamedHostsAddress) {
  const auto qos = QosOf("network.discovery=server");
  const auto& d = qos.wire_protocol().builtin.discovery_config;
  EXPECT_EQ(d.discoveryProtocol, eprosima::fastrtps::rtps::DiscoveryProtocol_t::CLIENT);
  ASSERT_EQ(d.m_DiscoveryServers.size(), 1u);
  const auto& server = d.m_DiscoveryServers.front();
  ASSERT_EQ(server.metatrafficUnicastLocatorList.size(), 1u);
  const auto& l = *server.metatrafficUnicastLocatorList.begin();
  EXPECT_EQ(eprosima::fastrtps::rtps::IPLocator::ip_to_string(l), "10.77.0.1");
  EXPECT_EQ(l.port, 11811u);
  std::ostringstream prefix;
  prefix << server.guidPrefix;
  EXPECT_EQ(prefix.str(), "44.53.00.5f.45.50.52.4f.53.49.4d.41");
}

TEST(NetworkQos, SharedMemoryComesFirstUnlessAWatcherAsksForUdpOnly) {
  std::vector<Diagnostic> diags;
  const Graph g = Parse(kSplit, &diags, {"network.transport=shm+udp"});
  ASSERT_TRUE(diags.empty());
  eprosima::fastdds::dds::DomainParticipantQos qos, watcher;
  ASSERT_TRUE(ApplyNetwork(g.network, false, &qos).ok());
  ASSERT_TRUE(ApplyNetwork(g.network, true, &watcher).ok());
  ASSERT_EQ(qos.transport().user_transports.size(), 2u);
  EXPECT_NE(std::dynamic_pointer_cast<eprosima::fastdds::rtps::SharedMemTransportDescriptor>(qos.transport().user_transports[0]), nullptr);
  EXPECT_EQ(watcher.transport().user_transports.size(), 1u);
}

// With a discovery server only the server watches a client's lease: an outage must end it less
// easily (docs/distributed.md, "A pulled cable").
TEST(NetworkQos, ParticipantsAnnounceEveryTenthOfTheLeaseWithADiscoveryServer) {
  NetworkConfig net;
  net.lease_s = 5;
  EXPECT_DOUBLE_EQ(AnnouncementPeriodS(net), 1.25);
  net.discovery = Discovery::kServer;
  net.server_address = "127.0.0.1";
  net.server_port = 11811;
  EXPECT_DOUBLE_EQ(AnnouncementPeriodS(net), 0.5);
  eprosima::fastdds::dds::DomainParticipantQos qos;
  ASSERT_TRUE(ApplyNetwork(net, false, &qos).ok());
  EXPECT_EQ(qos.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod,
            eprosima::fastrtps::Duration_t(0.5));
}

// A secured participant leases at least kSecuredLeaseS (Fast DDS 2.9 cannot authenticate again a
// peer that dropped it while it still holds that peer: network_qos.hpp), announcing as lease_s says.
TEST(NetworkQos, ASecuredParticipantLeasesAtLeastTwentySecondsAndAnnouncesAsBefore) {
  NetworkConfig net;
  net.lease_s = 5;
  eprosima::fastdds::dds::DomainParticipantQos open, secured, long_lease;
  secured.properties().properties().emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
  long_lease.properties().properties().emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
  ASSERT_TRUE(ApplyNetwork(net, false, &open).ok());
  ASSERT_TRUE(ApplyNetwork(net, false, &secured).ok());
  const auto& s = secured.wire_protocol().builtin.discovery_config;
  EXPECT_EQ(open.wire_protocol().builtin.discovery_config.leaseDuration, eprosima::fastrtps::Duration_t(5.0));
  EXPECT_EQ(s.leaseDuration, eprosima::fastrtps::Duration_t(kSecuredLeaseS));
  EXPECT_EQ(s.leaseDuration_announcementperiod, eprosima::fastrtps::Duration_t(1.25));
  net.lease_s = 30;  // longer than the floor: kept
  ASSERT_TRUE(ApplyNetwork(net, false, &long_lease).ok());
  EXPECT_EQ(long_lease.wire_protocol().builtin.discovery_config.leaseDuration, eprosima::fastrtps::Duration_t(30.0));
}

// ...and without a topic's liveliness_ms its endpoints get an AUTOMATIC lease of lease_s, so a
// dead writer stops counting as alive as soon as in an open graph (not when its match ends).
TEST(NetworkQos, ASecuredEndpointWithoutLivelinessGetsTheNetworksLease) {
  NetworkConfig net;
  net.lease_s = 5;
  TopicQos plain, own, ros2;
  own.liveliness_ms = 200;
  ros2.ros2_name = "/joint_states";
  EXPECT_EQ(WithLeaseLiveliness(plain, true, net).liveliness_ms, 5000);
  EXPECT_EQ(WithLeaseLiveliness(plain, false, net).liveliness_ms, 0);  // open: as before
  EXPECT_EQ(WithLeaseLiveliness(own, true, net).liveliness_ms, 200);   // the topic's own kept
  EXPECT_EQ(WithLeaseLiveliness(ros2, true, net).liveliness_ms, 0);    // a ROS 2 writer offers none
}

TEST(NetworkQos, AnAddressThatDoesNotResolveNamesItsKey) {
  std::vector<Diagnostic> diags;
  const Graph g = Parse(Replace(kSplit, "mind: 10.77.0.2", "mind: no-such-host.invalid"), &diags);
  ASSERT_TRUE(diags.empty());
  eprosima::fastdds::dds::DomainParticipantQos qos;
  const Status s = ApplyNetwork(g.network, false, &qos);
  EXPECT_EQ(s.code(), Status::Code::kInvalidArgument);
  EXPECT_NE(s.message().find("network.hosts.mind"), std::string::npos) << s.ToString();
  EXPECT_NE(s.message().find("no-such-host.invalid"), std::string::npos) << s.ToString();
}

}  // namespace
}  // namespace dyad

namespace dyad {
namespace {

// One reading of "host:port" for network.peers, network.server, TCP listeners and
// `dyad discovery-server --listen`.
TEST(HostPort, SplitsAtTheLastColonAndChecksThePort) {
  HostPort hp;
  ASSERT_TRUE(ParseHostPort("10.0.0.1:7412", &hp, true));
  EXPECT_EQ(hp.host, "10.0.0.1");
  EXPECT_EQ(hp.port, 7412);
  ASSERT_TRUE(ParseHostPort("lab-pc", &hp, false));
  EXPECT_EQ(hp.host, "lab-pc");
  EXPECT_EQ(hp.port, 0);
  for (const char* bad : {"lab-pc", "", ":7412", "a:", "a:0", "a:65536", "a:123456", "a:-1", "a:12x", "a: 12"})
    EXPECT_FALSE(ParseHostPort(bad, &hp, true)) << bad;
  EXPECT_FALSE(ParseHostPort("", &hp, false));
  EXPECT_TRUE(ParseHostPort("a:65535", &hp, true));
}

}  // namespace
}  // namespace dyad
