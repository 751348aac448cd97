// The graph's `network:` section as Fast DDS participant QoS (internal to the runtime).
//
//   scope local:         this machine only (the default of a graph that names no other machine):
//                        UDP bound to 127.0.0.1, shared memory, no multicast, discovery by
//                        unicast to 127.0.0.1's well-known ports (kLocalParticipants ids).
//                        Everything below is scope lan.
//   discovery multicast: Fast DDS's default SPDP (multicast 239.255.0.1 plus unicast).
//   discovery peers:     no multicast at all: a unicast metatraffic locator (all interfaces, the
//                        well-known port) and the initial peers list: every address of
//                        `network.hosts` and `network.peers` (a peer without a port is tried on
//                        the well-known ports of participant ids 0..kPeerParticipants-1).
//   discovery server:    a Fast DDS discovery-server client of `network.server`.
//   transport:           shared memory + UDPv4, UDPv4 only, or TCPv4: each process listens on its
//                        tcp_port and connects to the listeners of the processes named before it
//                        (one connection per pair); a watcher only connects, to all.
//                        `interfaces` is the allow-list.
//   lease_s:             the participant lease; announcements every lease/4 (lease/10 with a discovery server).
//                        A participant with DDS Security (ApplySecurity before ApplyNetwork) leases
//                        at least kSecuredLeaseS, announcing as often as lease_s says (see below).
#pragma once

#include <string>

#include <dyad/graph.hpp>
#include <dyad/status.hpp>

#include "graph/topic_qos.hpp"

namespace eprosima::fastdds::dds {
class DomainParticipantQos;
}

namespace dyad {

// Participant ids a peer address is tried on (Fast DDS's default is 4): each process and each
// watcher (`dyad echo`, `dyad status`) on a host takes one.
inline constexpr int kPeerParticipants = 12;
// network.scope local: participant ids announced to on 127.0.0.1 (every process and watcher of
// this machine on the domain; one beyond them is still found, as it announces to these).
inline constexpr int kLocalParticipants = 32;

// The shortest lease a secured participant announces. Fast DDS 2.9 cannot authenticate a peer
// again while that peer still holds it as authenticated: a peer that dropped us when our lease
// ran out (and rediscovered us at our next announcement) sends a handshake request the other side
// ignores (SecurityManager: a request for a participant in AUTHENTICATION_OK is "not mine"), or
// waits for one it never sends; neither sees the other again until our lease runs out there too,
// which our announcements prevent. Under load a participant can go a few seconds without reading
// its socket (its handshakes' ECDSA and Diffie-Hellman run on the thread that reads it), long
// enough for lease_s: 5 to run out. 20 s is Fast DDS's default lease. dyad's own notice of a
// process that is gone does not wait for it (dyad/processes, the launchers' link).
inline constexpr double kSecuredLeaseS = 20;

// What a secured participant's endpoint of a topic without `liveliness_ms` gets instead: an
// AUTOMATIC liveliness lease of lease_s, so that a writer whose process died still stops counting
// as alive after lease_s (not after kSecuredLeaseS, when its match ends). ROS 2 topics are left
// as they are (a ROS 2 writer offers no lease: a reader asking for one would not match it).
TopicQos WithLeaseLiveliness(const TopicQos& qos, bool secured, const NetworkConfig& network);

// The discovery server's GUID prefix (Fast DDS's convention for server id 0, the one
// `fast-discovery-server -i 0` uses too).
inline constexpr const char* kDiscoveryServerPrefix = "44.53.00.5f.45.50.52.4f.53.49.4d.41";

// `udp_only`: no shared memory whatever the section says (watchers: see DdsParticipant).
// `process`: whose participant this is (its TCP listener); empty for a watcher.
// InvalidArgument when an address does not resolve (naming the key).
Status ApplyNetwork(const NetworkConfig& network, bool udp_only, eprosima::fastdds::dds::DomainParticipantQos* qos,
                    const std::string& process = "");

// How often a participant announces itself: lease/4, or lease/10 with a discovery server (see
// network_qos.cpp for why).
double AnnouncementPeriodS(const NetworkConfig& network);

// Whether this machine can talk on the network now: a non-loopback IPv4 interface (of the
// `interfaces` allow-list, when there is one) is up and running (has carrier). True when the
// machine has no such interface at all (a one-machine graph over loopback). A participant made
// while it is false announces loopback locators only and is never reached once the cable is back.
bool NetworkUp(const NetworkConfig& network);

// An IPv4 address in dotted form for `name` (an address or a DNS name).
StatusOr<std::string> ResolveIPv4(const std::string& name);

}  // namespace dyad
