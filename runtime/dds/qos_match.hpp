// Whether a writer's QoS serves a reader's, on the terms Fast DDS 2.9 matches them by
// (EDP::valid_matching: reliability, durability, ownership, deadline, positive acks, liveliness).
//
// Fast DDS checks these before it looks at partitions, so its incompatible-QoS callbacks fire for
// an endpoint of another partition too (another run's on the same domain, which would never match
// anyway), and they do not say which remote endpoint it was. The discovery listener keeps each
// remote endpoint's terms (from its discovery data) to tell whose QoS it was: a report is ours
// only when an endpoint of our own run's partition is the incompatible one. Internal to
// runtime/dds/.
#pragma once

#include <string>
#include <vector>

#include <fastdds/dds/core/policy/QosPolicies.hpp>

namespace eprosima::fastdds::dds {
class DataReaderQos;
class DataWriterQos;
class ReaderQos;
class WriterQos;
}  // namespace eprosima::fastdds::dds

namespace dyad {

struct MatchTerms {
  eprosima::fastdds::dds::ReliabilityQosPolicyKind reliability = eprosima::fastdds::dds::BEST_EFFORT_RELIABILITY_QOS;
  eprosima::fastdds::dds::DurabilityQosPolicyKind durability = eprosima::fastdds::dds::VOLATILE_DURABILITY_QOS;
  eprosima::fastdds::dds::OwnershipQosPolicyKind ownership = eprosima::fastdds::dds::SHARED_OWNERSHIP_QOS;
  eprosima::fastrtps::Duration_t deadline = eprosima::fastrtps::c_TimeInfinite;
  eprosima::fastdds::dds::LivelinessQosPolicyKind liveliness = eprosima::fastdds::dds::AUTOMATIC_LIVELINESS_QOS;
  eprosima::fastrtps::Duration_t lease = eprosima::fastrtps::c_TimeInfinite;
  bool disable_positive_acks = false;
};

// A local endpoint's terms, and a remote one's from its discovery data.
MatchTerms TermsOf(const eprosima::fastdds::dds::DataReaderQos& q);
MatchTerms TermsOf(const eprosima::fastdds::dds::DataWriterQos& q);
MatchTerms TermsOf(const eprosima::fastdds::dds::ReaderQos& q);
MatchTerms TermsOf(const eprosima::fastdds::dds::WriterQos& q);

// The policies on which `writer` cannot serve `reader`, in Fast DDS's order; empty: compatible.
std::vector<eprosima::fastdds::dds::QosPolicyId_t> IncompatiblePolicies(const MatchTerms& writer, const MatchTerms& reader);

// "reliability", "liveliness", ...; "policy N" for one without a name here.
std::string QosPolicyName(eprosima::fastdds::dds::QosPolicyId_t id);

}  // namespace dyad
