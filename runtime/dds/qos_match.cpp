// The matching rules of Fast DDS 2.9's EDP::valid_matching (src/cpp/rtps/builtin/discovery/
// endpoint/EDP.cpp), the QoS part, term by term.
#include "dds/qos_match.hpp"

#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/publisher/qos/WriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/subscriber/qos/ReaderQos.hpp>

namespace dyad {

namespace fdds = eprosima::fastdds::dds;

namespace {

// A local entity's QoS (DataReaderQos, DataWriterQos: accessors), and a remote endpoint's as
// discovery carries it (ReaderQos, WriterQos: members); the acks term differs by side.
template <typename EntityQos>
MatchTerms EntityTerms(const EntityQos& q, bool disable_positive_acks) {
  return MatchTerms{q.reliability().kind, q.durability().kind,           q.ownership().kind,   q.deadline().period,
                    q.liveliness().kind,  q.liveliness().lease_duration, disable_positive_acks};
}

template <typename ProxyQos>
MatchTerms ProxyTerms(const ProxyQos& q) {
  return MatchTerms{q.m_reliability.kind,
                    q.m_durability.kind,
                    q.m_ownership.kind,
                    q.m_deadline.period,
                    q.m_liveliness.kind,
                    q.m_liveliness.lease_duration,
                    q.m_disablePositiveACKs.enabled};
}

}  // namespace

MatchTerms TermsOf(const fdds::DataReaderQos& q) { return EntityTerms(q, q.reliable_reader_qos().disable_positive_ACKs.enabled); }
MatchTerms TermsOf(const fdds::DataWriterQos& q) { return EntityTerms(q, q.reliable_writer_qos().disable_positive_acks.enabled); }
MatchTerms TermsOf(const fdds::ReaderQos& q) { return ProxyTerms(q); }
MatchTerms TermsOf(const fdds::WriterQos& q) { return ProxyTerms(q); }

std::vector<fdds::QosPolicyId_t> IncompatiblePolicies(const MatchTerms& writer, const MatchTerms& reader) {
  std::vector<fdds::QosPolicyId_t> out;
  if (writer.reliability == fdds::BEST_EFFORT_RELIABILITY_QOS && reader.reliability == fdds::RELIABLE_RELIABILITY_QOS)
    out.push_back(fdds::RELIABILITY_QOS_POLICY_ID);
  if (writer.durability < reader.durability) out.push_back(fdds::DURABILITY_QOS_POLICY_ID);
  if (writer.ownership != reader.ownership) out.push_back(fdds::OWNERSHIP_QOS_POLICY_ID);
  if (writer.deadline > reader.deadline) out.push_back(fdds::DEADLINE_QOS_POLICY_ID);
  if (!writer.disable_positive_acks && reader.disable_positive_acks) out.push_back(fdds::DISABLEPOSITIVEACKS_QOS_POLICY_ID);
  if (writer.lease > reader.lease || writer.liveliness < reader.liveliness) out.push_back(fdds::LIVELINESS_QOS_POLICY_ID);
  return out;
}

std::string QosPolicyName(fdds::QosPolicyId_t id) {
  switch (id) {
    case fdds::RELIABILITY_QOS_POLICY_ID:
      return "reliability";
    case fdds::DURABILITY_QOS_POLICY_ID:
      return "durability";
    case fdds::OWNERSHIP_QOS_POLICY_ID:
      return "ownership";
    case fdds::DEADLINE_QOS_POLICY_ID:
      return "deadline";
    case fdds::DISABLEPOSITIVEACKS_QOS_POLICY_ID:
      return "disable-positive-acks";
    case fdds::LIVELINESS_QOS_POLICY_ID:
      return "liveliness";
    case fdds::HISTORY_QOS_POLICY_ID:
      return "history";
    default:
      return "policy " + std::to_string(static_cast<int>(id));
  }
}

}  // namespace dyad
