// "host:port" as graph files and the command line write it (network.peers, network.server,
// `dyad discovery-server --listen`, TCP listeners): one reading for all of them.
#pragma once

#include <string>

namespace dyad {

struct HostPort {
  std::string host;
  int port = 0;  // 0: none given
};

// Splits at the last ':'. Returns false when the host is empty, or a port is given that is not
// 1..65535 in decimal, or (port_required) none is given.
inline bool ParseHostPort(const std::string& text, HostPort* out, bool port_required) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos) {
    *out = HostPort{text, 0};
    return !port_required && !text.empty();
  }
  const std::string port = text.substr(colon + 1);
  if (colon == 0 || port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos) return false;
  *out = HostPort{text.substr(0, colon), std::stoi(port)};
  return out->port >= 1 && out->port <= 65535;
}

}  // namespace dyad
