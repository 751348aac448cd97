#include "dds/network_qos.hpp"

#include "graph/host_port.hpp"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netdb.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <fastdds/rtps/attributes/PropertyPolicy.h>
#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastdds/rtps/transport/TCPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

namespace rtps = eprosima::fastrtps::rtps;

namespace dyad {

StatusOr<std::string> ResolveIPv4(const std::string& name) {
  in_addr a{};
  if (inet_pton(AF_INET, name.c_str(), &a) == 1) return name;
  addrinfo hints{};
  hints.ai_family = AF_INET;
  addrinfo* res = nullptr;
  if (getaddrinfo(name.c_str(), nullptr, &hints, &res) != 0 || res == nullptr)
    return Status::InvalidArgument("'" + name + "' is neither an IPv4 address nor a host name this machine resolves");
  char buf[INET_ADDRSTRLEN] = {0};
  inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(res->ai_addr)->sin_addr, buf, sizeof(buf));
  freeaddrinfo(res);
  return std::string(buf);
}

double AnnouncementPeriodS(const NetworkConfig& net) {
  // With a discovery server, the server alone watches each client's lease and tells the others
  // when it ends (clients never lease each other). The silence it sees after a pulled cable is
  // the outage plus up to two announcement periods; if that ends the lease just as the client
  // comes back, Fast DDS 2.9's server database discards the client's return and orphans its
  // endpoints (docs/distributed.md, "A pulled cable"). Announcing every lease/10 keeps any
  // outage shorter than 0.8 lease from ending the lease at all.
  return net.discovery == Discovery::kServer ? net.lease_s / 10 : net.lease_s / 4;
}

TopicQos WithLeaseLiveliness(const TopicQos& qos, bool secured, const NetworkConfig& net) {
  TopicQos q = qos;
  if (secured && q.liveliness_ms <= 0 && q.ros2_name.empty()) q.liveliness_ms = net.lease_s * 1000;
  return q;
}

bool NetworkUp(const NetworkConfig& net) {
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return true;  // cannot tell: do not hold anything back
  bool any = false, up = false;
  for (ifaddrs* i = list; i != nullptr; i = i->ifa_next) {
    if (i->ifa_addr == nullptr || i->ifa_addr->sa_family != AF_INET || (i->ifa_flags & IFF_LOOPBACK)) continue;
    char address[INET_ADDRSTRLEN] = {0};
    inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(i->ifa_addr)->sin_addr, address, sizeof(address));
    const bool allowed = net.interfaces.empty() ||
                         std::find_if(net.interfaces.begin(), net.interfaces.end(), [&](const std::string& n) {
                           return n == i->ifa_name || n == address;
                         }) != net.interfaces.end();
    if (!allowed) continue;
    any = true;
    up |= (i->ifa_flags & IFF_UP) && (i->ifa_flags & IFF_RUNNING);
  }
  freeifaddrs(list);
  return !any || up;
}

namespace {

// Fast DDS 2.9 matches its interface whitelist against addresses only (IPFinder's info_IP.name),
// so an interface named in `network.interfaces` (eth0) is turned into its IPv4 addresses here.
// An entry that is neither stays as written: Fast DDS ignores it on this machine.
std::vector<std::string> WhitelistAddresses(const std::vector<std::string>& entries) {
  std::vector<std::string> out;
  ifaddrs* list = nullptr;
  const bool have_list = getifaddrs(&list) == 0;
  for (const std::string& e : entries) {
    in_addr a{};
    bool named = false;
    if (inet_pton(AF_INET, e.c_str(), &a) != 1 && have_list) {
      for (ifaddrs* i = list; i != nullptr; i = i->ifa_next) {
        if (i->ifa_addr == nullptr || i->ifa_addr->sa_family != AF_INET || e != i->ifa_name) continue;
        char address[INET_ADDRSTRLEN] = {0};
        inet_ntop(AF_INET, &reinterpret_cast<sockaddr_in*>(i->ifa_addr)->sin_addr, address, sizeof(address));
        out.push_back(address);
        named = true;
      }
    }
    if (!named) out.push_back(e);
  }
  if (have_list) freeifaddrs(list);
  return out;
}

StatusOr<rtps::Locator_t> UdpLocator(const std::string& text, const std::string& key) {
  HostPort hp;
  if (!ParseHostPort(text, &hp, false)) return Status::InvalidArgument(key + ": '" + text + "' is not address or address:port");
  const uint32_t port = static_cast<uint32_t>(hp.port);
  auto address = ResolveIPv4(hp.host);
  if (!address.ok()) return address.status().WithContext(key);
  rtps::Locator_t l;
  l.kind = LOCATOR_KIND_UDPv4;
  rtps::IPLocator::setIPv4(l, address.value());
  l.port = port;
  return l;
}

}  // namespace

Status ApplyNetwork(const NetworkConfig& net, bool udp_only, eprosima::fastdds::dds::DomainParticipantQos* qos,
                    const std::string& process) {
  auto& transport = qos->transport();
  transport.use_builtin_transports = false;
  transport.user_transports.clear();
  auto& builtin = qos->wire_protocol().builtin;
  const bool secured =
      eprosima::fastrtps::rtps::PropertyPolicyHelper::find_property(qos->properties(), "dds.sec.auth.plugin") != nullptr;
  builtin.discovery_config.leaseDuration =
      eprosima::fastrtps::Duration_t(secured ? std::max(net.lease_s, kSecuredLeaseS) : net.lease_s);
  builtin.discovery_config.leaseDuration_announcementperiod = eprosima::fastrtps::Duration_t(AnnouncementPeriodS(net));
  if (net.transport == NetTransport::kTcp) {
    auto tcp = std::make_shared<eprosima::fastdds::rtps::TCPv4TransportDescriptor>();
    tcp->interfaceWhiteList = WhitelistAddresses(net.interfaces);
    HostPort own;
    if (auto it = net.tcp_listeners.find(process); it != net.tcp_listeners.end() && ParseHostPort(it->second, &own, true))
      tcp->add_listener_port(static_cast<uint16_t>(own.port));
    transport.user_transports.push_back(tcp);
    // One connection per pair: a process connects to the listeners of the processes named before
    // it (they connect to none of its own); a watcher, with no listener, to all. When both sides
    // of a pair connected at once, Fast DDS 2.9 dropped both connections and the pair never met.
    for (const auto& [other, listener] : net.tcp_listeners) {
      if (!process.empty() && other >= process) continue;
      auto l = UdpLocator(listener, "processes." + other + ".tcp_port");
      if (!l.ok()) return l.status();
      rtps::Locator_t peer = l.value();
      peer.kind = LOCATOR_KIND_TCPv4;
      rtps::IPLocator::setPhysicalPort(peer, static_cast<uint16_t>(peer.port));
      rtps::IPLocator::setLogicalPort(peer, 0);
      builtin.initialPeersList.push_back(peer);
    }
    return Status::OK();
  }
  if (!udp_only && net.transport == NetTransport::kShmUdp)
    transport.user_transports.push_back(std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>());
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->interfaceWhiteList = WhitelistAddresses(net.interfaces);
  udp->maxInitialPeersRange = kPeerParticipants;
  transport.user_transports.push_back(udp);

  if (net.scope == NetScope::kLocal && net.discovery == Discovery::kMulticast) {
    // This machine only: every socket bound to loopback (Fast DDS 2.9 whitelists by address), no
    // multicast (loopback has none), discovery by unicast to this machine's well-known ports.
    udp->interfaceWhiteList = {"127.0.0.1"};
    udp->maxInitialPeersRange = kLocalParticipants;
    rtps::Locator_t any;
    any.kind = LOCATOR_KIND_UDPv4;
    builtin.metatrafficUnicastLocatorList.push_back(any);
    rtps::Locator_t self;
    self.kind = LOCATOR_KIND_UDPv4;
    rtps::IPLocator::setIPv4(self, "127.0.0.1");
    builtin.initialPeersList.push_back(self);
  } else if (net.discovery == Discovery::kPeers) {
    // A unicast metatraffic locator (address and port left to Fast DDS: every allowed interface,
    // the well-known port) keeps Fast DDS from creating the multicast one.
    rtps::Locator_t any;
    any.kind = LOCATOR_KIND_UDPv4;
    builtin.metatrafficUnicastLocatorList.push_back(any);
    for (const auto& [host, address] : net.hosts) {
      auto l = UdpLocator(address, "network.hosts." + host);
      if (!l.ok()) return l.status();
      builtin.initialPeersList.push_back(l.value());
    }
    for (const auto& p : net.peers) {
      auto l = UdpLocator(p, "network.peers");
      if (!l.ok()) return l.status();
      builtin.initialPeersList.push_back(l.value());
    }
  } else if (net.discovery == Discovery::kServer) {
    auto l = UdpLocator(net.server_address + ":" + std::to_string(net.server_port), "network.server");
    if (!l.ok()) return l.status();
    builtin.discovery_config.discoveryProtocol = rtps::DiscoveryProtocol_t::CLIENT;
    eprosima::fastdds::rtps::RemoteServerAttributes server;
    server.ReadguidPrefix(kDiscoveryServerPrefix);
    server.metatrafficUnicastLocatorList.push_back(l.value());
    builtin.discovery_config.m_DiscoveryServers.push_back(server);
  }
  return Status::OK();
}

}  // namespace dyad
