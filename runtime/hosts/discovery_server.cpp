#include "dyad/discovery_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <ostream>
#include <sstream>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include "dyad/interrupt.hpp"
#include "dds/network_qos.hpp"
#include "graph/host_port.hpp"

namespace fdds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

namespace dyad {
namespace {

// OK when a UDP socket can be bound to address:port on this machine now.
Status CanBindUdp(const std::string& address, int port) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) return Status::IOError(std::string("socket: ") + std::strerror(errno));
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  ::inet_pton(AF_INET, address.c_str(), &a.sin_addr);
  const int rc = ::bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof(a));
  const int error = errno;
  ::close(fd);
  if (rc == 0) return Status::OK();
  const std::string where = "cannot listen on " + address + ":" + std::to_string(port);
  if (error == EADDRNOTAVAIL) return Status::InvalidArgument(where + ": " + address + " is not an address of this machine");
  if (error == EADDRINUSE) return Status::IOError(where + ": the port is taken");
  return Status::IOError(where + ": " + std::strerror(error));
}

}  // namespace

int RunDiscoveryServer(const std::string& listen, std::ostream& out, std::ostream& err) {
  HostPort hp;
  if (!ParseHostPort(listen, &hp, true)) {
    err << "dyad discovery-server: --listen " << listen << ": expected ADDRESS:PORT (port 1..65535)\n";
    return 2;
  }
  const int port = hp.port;
  auto address = ResolveIPv4(hp.host);
  if (!address.ok()) {
    err << "dyad discovery-server: --listen " << listen << ": " << address.status().message() << "\n";
    return 2;
  }
  // Fast DDS opens its socket on every interface and would announce any address given, so a
  // wrong one (not this machine's) would run and never be reached: bind it ourselves first.
  if (Status here = CanBindUdp(address.value(), port); !here.ok()) {
    err << "dyad discovery-server: --listen " << listen << ": " << here.message() << "\n";
    return 1;
  }
  std::mutex mutex;
  std::condition_variable cv;
  InterruptWatcher interrupt([&](int) {
    std::lock_guard<std::mutex> lock(mutex);  // the waiter is either before its check or waiting
    cv.notify_all();
  });

  auto* factory = fdds::DomainParticipantFactory::get_instance();
  factory->load_profiles();
  fdds::DomainParticipantQos qos = factory->get_default_participant_qos();
  qos.name("dyad/discovery-server");
  qos.transport().use_builtin_transports = false;
  qos.transport().user_transports.push_back(std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>());
  auto& builtin = qos.wire_protocol().builtin;
  builtin.discovery_config.discoveryProtocol = rtps::DiscoveryProtocol_t::SERVER;
  std::istringstream prefix(kDiscoveryServerPrefix);
  prefix >> qos.wire_protocol().prefix;
  rtps::Locator_t locator;
  locator.kind = LOCATOR_KIND_UDPv4;
  rtps::IPLocator::setIPv4(locator, address.value());
  locator.port = static_cast<uint32_t>(port);
  builtin.metatrafficUnicastLocatorList.push_back(locator);
  fdds::DomainParticipant* participant = factory->create_participant(0, qos);
  if (participant == nullptr) {
    err << "dyad discovery-server: cannot listen on " << address.value() << ":" << port
        << " (is the port taken, or the address not this machine's?)\n";
    return 1;
  }
  out << "dyad discovery-server: listening on " << address.value() << ":" << port << " (UDP)" << std::endl;
  {
    std::unique_lock<std::mutex> lock(mutex);
    cv.wait(lock, [&] { return interrupt.signal() != 0; });
  }
  factory->delete_participant(participant);
  return ExitCodeForSignal(interrupt.signal());
}

}  // namespace dyad
