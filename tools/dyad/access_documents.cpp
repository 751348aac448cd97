#include "access_documents.hpp"

#include <set>
#include <sstream>

#include <dyad/security.hpp>

namespace dyad::cli {
namespace {

// The runtime's own topics a process writes and reads (runtime/graph/runtime_topics.hpp).
const std::set<std::string> kProcessWrites = {"dyad/processes", "dyad/stats", "dyad/health", "dyad/clock", "dyad/clock_offsets",
                                               "dyad/params"};
const std::set<std::string> kProcessReads = {"dyad/processes", "dyad/clock", "dyad/param_requests"};
// A host's identity also asks for live parameter changes (`dyad param set` on a lab machine).
const std::set<std::string> kLauncherWrites = {"dyad/launchers", "dyad/processes", "dyad/param_requests"};

std::string Escaped(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

void Criteria(std::ostream& x, const char* what, const std::set<std::string>& topics, const std::string& partition) {
  if (topics.empty()) return;
  x << "        <" << what << ">\n          <topics>\n";
  for (const std::string& t : topics) x << "            <topic>" << Escaped(t) << "</topic>\n";
  x << "          </topics>\n          <partitions>\n            <partition>" << Escaped(partition)
    << "</partition>\n          </partitions>\n        </" << what << ">\n";
}

const char* kDomains = "<domains><id_range><min>0</min><max>232</max></id_range></domains>";

}  // namespace

std::string GovernanceXml() {
  std::ostringstream x;
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
       "<!-- dyad security init: the domain's rules (dyad/security.hpp) -->\n"
       "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
       "xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd\">\n"
       "  <domain_access_rules>\n    <domain_rule>\n      "
    << kDomains
    << "\n"
       "      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>\n"
       "      <enable_join_access_control>true</enable_join_access_control>\n"
       "      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>\n"
       "      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>\n"
       "      <rtps_protection_kind>SIGN</rtps_protection_kind>\n"
       "      <topic_access_rules>\n        <topic_rule>\n"
       "          <topic_expression>*</topic_expression>\n"
       "          <enable_discovery_protection>true</enable_discovery_protection>\n"
       "          <enable_liveliness_protection>true</enable_liveliness_protection>\n"
       "          <enable_read_access_control>true</enable_read_access_control>\n"
       "          <enable_write_access_control>true</enable_write_access_control>\n"
       "          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>\n"
       "          <data_protection_kind>ENCRYPT</data_protection_kind>\n"
       "        </topic_rule>\n      </topic_access_rules>\n"
       "    </domain_rule>\n  </domain_access_rules>\n</dds>\n";
  return x.str();
}

std::string PermissionsXml(const Graph& graph, const std::string& identity, const std::string& subject,
                           const std::map<std::string, TopicAccess>& access, const std::string& not_before,
                           const std::string& not_after) {
  std::set<std::string> publish, subscribe;
  const std::string process_prefix = "process.";
  if (identity.rfind(process_prefix, 0) == 0) {
    publish = kProcessWrites;
    subscribe = kProcessReads;
    if (auto it = access.find(identity.substr(process_prefix.size())); it != access.end()) {
      publish.insert(it->second.writes.begin(), it->second.writes.end());
      subscribe.insert(it->second.reads.begin(), it->second.reads.end());
    }
  } else if (identity == kGuestIdentity) {
    // Exactly the graph's grant: a guest announces nothing on the runtime's topics (dyad/guest.hpp).
    publish = {graph.security.guest_publish.begin(), graph.security.guest_publish.end()};
    subscribe = {graph.security.guest_subscribe.begin(), graph.security.guest_subscribe.end()};
  } else {
    publish = kLauncherWrites;
    subscribe = {"*"};
  }
  // Sent in clear in every handshake: it names nothing of the graph (access_documents.hpp).
  const std::string partition = "dyad/*";
  std::ostringstream x;
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
       "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
       "xsi:noNamespaceSchemaLocation=\"http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd\">\n"
       "  <permissions>\n    <grant name=\"grant\">\n      <subject_name>"
    << Escaped(subject) << "</subject_name>\n"
    << "      <validity>\n        <not_before>" << not_before << "</not_before>\n        <not_after>" << not_after
    << "</not_after>\n      </validity>\n      <allow_rule>\n        " << kDomains << "\n";
  Criteria(x, "publish", publish, partition);
  Criteria(x, "subscribe", subscribe, partition);
  x << "      </allow_rule>\n      <default>DENY</default>\n    </grant>\n  </permissions>\n</dds>\n";
  return x.str();
}

}  // namespace dyad::cli
