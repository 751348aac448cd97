// DDS Security for one participant, as Fast DDS participant properties (internal to the runtime;
// the keystore and its identities: dyad/security.hpp).
//
// builtin.PKI-DH authenticates with the identity's certificate and key against the identity CA;
// builtin.Access-Permissions enforces the signed governance (no unauthenticated participant,
// discovery, liveliness and data encrypted) and the identity's signed permissions;
// builtin.AES-GCM-GMAC encrypts. Nothing is set for IdentityFiles without a certificate.
// Nothing named in clear (dyad/wire_names.hpp): the participant's name becomes its WireName with
// the keystore's names key (names.key beside the identity CA's certificate), and Fast DDS's
// statistics properties, which would announce this machine's host name, user name and process
// id in every discovery announcement, are removed. Returns the names key ("" without security),
// with which the participant reads its peers' names back.
// security_qos.cpp also holds DdsParticipant::SecurityHint: what the error of an endpoint refused
// on a secured participant adds (the permissions, and how to renew them).
#pragma once

#include <string>

#include <dyad/security.hpp>
#include <dyad/status.hpp>

namespace eprosima::fastdds::dds {
class DomainParticipantQos;
}

namespace dyad {

StatusOr<std::string> ApplySecurity(const IdentityFiles& identity, eprosima::fastdds::dds::DomainParticipantQos* qos);

}  // namespace dyad
