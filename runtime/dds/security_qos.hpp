// DDS Security for one participant, as Fast DDS participant properties (internal to the runtime;
// the keystore and its identities: dyad/security.hpp).
//
// builtin.PKI-DH authenticates with the identity's certificate and key against the identity CA;
// builtin.Access-Permissions enforces the signed governance (no unauthenticated participant,
// discovery, liveliness and data encrypted) and the identity's signed permissions;
// builtin.AES-GCM-GMAC encrypts. Nothing is set for IdentityFiles without a certificate.
// security_qos.cpp also holds DdsParticipant::SecurityHint: what the error of an endpoint refused
// on a secured participant adds (the permissions, and how to renew them).
#pragma once

#include <dyad/security.hpp>

namespace eprosima::fastdds::dds {
class DomainParticipantQos;
}

namespace dyad {

void ApplySecurity(const IdentityFiles& identity, eprosima::fastdds::dds::DomainParticipantQos* qos);

}  // namespace dyad
