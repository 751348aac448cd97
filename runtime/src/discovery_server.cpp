#include "dyad/discovery_server.hpp"

#include <condition_variable>
#include <mutex>
#include <ostream>
#include <sstream>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include "dyad/interrupt.hpp"
#include "network_qos.hpp"

namespace fdds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

namespace dyad {

int RunDiscoveryServer(const std::string& listen, std::ostream& out, std::ostream& err) {
  const auto colon = listen.rfind(':');
  int port = 0;
  if (colon != std::string::npos && colon + 1 < listen.size() && listen.size() - colon - 1 <= 5 &&
      listen.find_first_not_of("0123456789", colon + 1) == std::string::npos)
    port = std::stoi(listen.substr(colon + 1));
  if (colon == std::string::npos || port < 1 || port > 65535) {
    err << "dyad discovery-server: --listen " << listen << ": expected ADDRESS:PORT (port 1..65535)\n";
    return 2;
  }
  auto address = ResolveIPv4(listen.substr(0, colon));
  if (!address.ok()) {
    err << "dyad discovery-server: --listen " << listen << ": " << address.status().message() << "\n";
    return 2;
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
