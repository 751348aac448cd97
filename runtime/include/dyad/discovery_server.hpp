// dyad/discovery_server.hpp — a Fast DDS discovery server, for graphs whose network says
// `discovery: server` (docs/distributed.md).
//
// RunDiscoveryServer listens on ADDRESS:PORT (UDP) as Fast DDS server id 0 (GUID prefix
// 44.53.00.5f.45.50.52.4f.53.49.4d.41, the one `fast-discovery-server -i 0` uses, so either can
// serve the other's clients) until SIGINT or SIGTERM. The launcher of the host that
// `network.server` names starts it as `dyad discovery-server --listen ADDRESS:PORT` before the
// graph's processes; run it by hand for a server on a machine that runs no process of the graph.
//
// It runs until a signal, and returns 128 + signal then (the launcher's SIGTERM is its normal
// end); 2 for a malformed or unresolvable --listen, 1 when it cannot listen there (the port is
// taken, the address is not this machine's: checked by binding it first, since Fast DDS would
// open every interface, announce the wrong address and never be reached).
#pragma once

#include <iosfwd>
#include <string>

namespace dyad {

int RunDiscoveryServer(const std::string& listen, std::ostream& out, std::ostream& err);

}  // namespace dyad
