#include "dds/security_qos.hpp"

#include "dds/dds_participant.hpp"

#include <filesystem>
#include <string>

#include <dyad/wire_names.hpp>

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

namespace dyad {

StatusOr<std::string> ApplySecurity(const IdentityFiles& identity, eprosima::fastdds::dds::DomainParticipantQos* qos) {
  if (!identity.enabled()) return std::string();
  auto key = ReadNamesKey((std::filesystem::path(identity.identity_ca).parent_path() / kNamesKeyFile).string());
  if (!key.ok()) return key.status();
  const std::string name = qos->name().to_string();
  if (name.size() > kMaxReadableName)  // the graph's names never are (graph.cpp): a caller's bug
    return Status::InvalidArgument("participant name '" + name + "' has " + std::to_string(name.size()) +
                                   " bytes: a secured graph's peers read back names of at most " +
                                   std::to_string(kMaxReadableName) + " (dyad/wire_names.hpp)");
  const std::string wire_name = WireName(key.value(), name);
  if (wire_name.empty()) return Status::Internal("cannot make the opaque name of '" + name + "' (libcrypto failed)");
  qos->name(wire_name);
  auto& p = qos->properties().properties();
  // Fast DDS fills these (when present and empty) with the host's and user's names and the pid,
  // and announces them in clear.
  std::erase_if(p, [](const eprosima::fastrtps::rtps::Property& x) { return x.name().rfind("fastdds.physical_data.", 0) == 0; });
  auto set = [&p](const std::string& name, const std::string& value) { p.emplace_back(name, value); };
  const std::string uri = "file://";
  set("dds.sec.auth.plugin", "builtin.PKI-DH");
  set("dds.sec.auth.builtin.PKI-DH.identity_ca", uri + identity.identity_ca);
  set("dds.sec.auth.builtin.PKI-DH.identity_certificate", uri + identity.certificate);
  set("dds.sec.auth.builtin.PKI-DH.private_key", uri + identity.private_key);
  set("dds.sec.access.plugin", "builtin.Access-Permissions");
  set("dds.sec.access.builtin.Access-Permissions.permissions_ca", uri + identity.permissions_ca);
  set("dds.sec.access.builtin.Access-Permissions.governance", uri + identity.governance);
  set("dds.sec.access.builtin.Access-Permissions.permissions", uri + identity.permissions);
  set("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
  return key;
}

// The security room of DdsParticipant (dds_internal.hpp): what an endpoint refused on a secured
// participant adds to its error.
std::string DdsParticipant::SecurityHint(const std::string& verb) const {
  if (!secured_) return "";
  return " (DDS Security: the permissions of participant '" + name_ + "' do not let it " + verb +
         " this topic; after changing the graph, rerun `dyad security init`)";
}

}  // namespace dyad
