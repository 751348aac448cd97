// Discovery and its reports (DdsParticipant::DiscoveryListener, dds_internal.hpp): the endpoints
// discovered on the domain (Discovered()), the names of their participants (a secured graph's read
// back from their opaque names on the wire: dyad/wire_names.hpp), and the problems that
// stop data where it should flow, reported through Options::on_problem: a remote endpoint on one
// of our topics with another type (same IDL name, other hash: a layout change, which Fast DDS
// would match silently or never match and say nothing), an incompatible QoS (one of this run's
// partition: Fast DDS reports another run's too, dds/qos_match.hpp); and, through
// Options::on_foreign_writer, once per writer, a writer of one of our topics in another run's
// partition. Fast DDS calls these on its threads; the listener's mutex_ guards what it keeps, and
// it takes the participant's mutex_ (never while holding its own) to read the topic maps.
#include "dds/dds_internal.hpp"

#include <dyad/ros2_names.hpp>
#include <dyad/wire_names.hpp>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/rtps/builtin/data/ParticipantProxyData.h>
#include <fastdds/rtps/builtin/data/ReaderProxyData.h>
#include <fastdds/rtps/builtin/data/WriterProxyData.h>

#include <fnmatch.h>

#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace dyad {
namespace {

std::string GuidPrefixString(const rtps::GuidPrefix_t& p) {
  std::ostringstream os;
  os << p;
  return os.str();
}

// DDS partition matching (DDS 1.4, 2.2.3.13): two endpoints share a partition when a name of
// one equals, or is matched by a pattern of, a name of the other; no names is the default
// partition "". Fast DDS matches the same way (fnmatch).
bool PartitionsMatch(const std::vector<std::string>& a, const std::vector<std::string>& b) {
  const std::vector<std::string> none{""};
  const auto& x = a.empty() ? none : a;
  const auto& y = b.empty() ? none : b;
  for (const auto& m : x)
    for (const auto& n : y)
      if (m == n || fnmatch(m.c_str(), n.c_str(), 0) == 0 || fnmatch(n.c_str(), m.c_str(), 0) == 0) return true;
  return false;
}

std::string PartitionText(const std::vector<std::string>& names) {
  if (names.empty()) return "the default partition";
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "'" : ", '") + n + "'";
  return "partition " + out;
}

}  // namespace

void DdsParticipant::DiscoveryListener::on_participant_discovery(fdds::DomainParticipant*,
                                                                 rtps::ParticipantDiscoveryInfo&& info) {
  const std::string prefix = GuidPrefixString(info.info.m_guid.guidPrefix);
  // A peer that left (REMOVED) or whose lease ran out (DROPPED) is forgotten, so that peers
  // coming and going (restarts, watchers, a stranger knocking with a new GUID each time) do not
  // grow the map. Fast DDS reports its endpoints' removal before its own.
  if (info.status == rtps::ParticipantDiscoveryInfo::REMOVED_PARTICIPANT ||
      info.status == rtps::ParticipantDiscoveryInfo::DROPPED_PARTICIPANT) {
    std::lock_guard<std::mutex> lock(mutex_);
    names_.erase(prefix);
    return;
  }
  // In a secured graph a peer's name on the wire is opaque; ours read back, others' kept as they are.
  std::string name = info.info.m_participantName.to_string();
  if (!names_key_.empty())
    if (std::string readable = ReadableName(names_key_, name); !readable.empty()) name = readable;
  std::lock_guard<std::mutex> lock(mutex_);
  names_[prefix] = name;
}

size_t DdsParticipant::DiscoveryListener::KnownPeers() {
  std::lock_guard<std::mutex> lock(mutex_);
  return names_.size();
}

// Remote endpoints are named by their DDS topic; ours by the graph's topic (a ROS 2 topic's
// DDS topic is "rt/...", in the default partition): compare in the graph's names.
void DdsParticipant::DiscoveryListener::on_publisher_discovery(fdds::DomainParticipant*,
                                                               rtps::WriterDiscoveryInfo&& info) {
  const bool gone = info.status == rtps::WriterDiscoveryInfo::REMOVED_WRITER;
  const std::string dds_topic = info.info.topicName().to_string();
  const bool same_partition = SharesPartition(dds_topic, info.info.m_qos.m_partition.names());
  Track(true, gone, dds_topic, info.info.typeName().to_string(), info.info.guid(), same_partition, TermsOf(info.info.m_qos));
  if (info.status != rtps::WriterDiscoveryInfo::DISCOVERED_WRITER) return;
  if (!same_partition) {
    Foreign(dds_topic, info.info.m_qos.m_partition.names(), info.info.guid());
    return;  // another run's: its type is not ours to check
  }
  Check("writer", dds_topic, info.info.typeName().to_string(), GuidPrefixString(info.info.guid().guidPrefix));
}

void DdsParticipant::DiscoveryListener::on_subscriber_discovery(fdds::DomainParticipant*,
                                                                rtps::ReaderDiscoveryInfo&& info) {
  const bool gone = info.status == rtps::ReaderDiscoveryInfo::REMOVED_READER;
  const std::string dds_topic = info.info.topicName().to_string();
  const bool same_partition = SharesPartition(dds_topic, info.info.m_qos.m_partition.names());
  Track(false, gone, dds_topic, info.info.typeName().to_string(), info.info.guid(), same_partition, TermsOf(info.info.m_qos));
  if (info.status != rtps::ReaderDiscoveryInfo::DISCOVERED_READER) return;
  if (!same_partition) return;
  Check("reader", dds_topic, info.info.typeName().to_string(), GuidPrefixString(info.info.guid().guidPrefix));
}

// Endpoints by the names this participant uses: a ROS 2 topic of ours by its graph name, any
// other ROS 2 topic by its ROS 2 name ("rt/a/b" -> "/a/b").
std::vector<DiscoveredEndpoint> DdsParticipant::DiscoveryListener::Snapshot() {
  std::map<std::string, std::string> ours;
  {
    std::lock_guard<std::mutex> lock(owner_->mutex_);
    ours = owner_->ros2_topics_;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<DiscoveredEndpoint> out;
  for (auto [guid, e] : endpoints_) {
    auto it = names_.find(e.participant);
    if (it != names_.end()) e.participant = it->second;
    if (auto our = ours.find(e.topic); our != ours.end()) e.topic = our->second;
    else if (std::string ros2 = Ros2NameOfDdsTopic(e.topic); !ros2.empty()) e.topic = ros2;
    out.push_back(e);
  }
  return out;
}

// A topic this participant has just begun to use: the endpoints discovered on it before (their
// discovery found no topic of ours to check them against) are checked now.
void DdsParticipant::DiscoveryListener::CheckDiscovered(const std::string& dds_topic) {
  std::vector<DiscoveredEndpoint> known;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [guid, e] : endpoints_)
      if (e.topic == dds_topic && e.same_partition) known.push_back(e);
  }
  for (const auto& e : known) Check(e.writer ? "writer" : "reader", dds_topic, e.type, e.participant);
}

// Fast DDS checks QoS before partitions (dds/qos_match.hpp), so these fire for another run's
// endpoints too, without saying whose: the remote endpoints of the topic are checked here, and
// only one of this run's partition is reported (once per remote endpoint, whichever of ours
// it fails).
void DdsParticipant::DiscoveryListener::on_requested_incompatible_qos(fdds::DataReader* reader,
                                                                      const fdds::RequestedIncompatibleQosStatus& status) {
  Incompatible(false, reader->get_topicdescription()->get_name(), TermsOf(reader->get_qos()), status.last_policy_id);
}

void DdsParticipant::DiscoveryListener::on_offered_incompatible_qos(fdds::DataWriter* writer,
                                                                    const fdds::OfferedIncompatibleQosStatus& status) {
  Incompatible(true, writer->get_topic()->get_name(), TermsOf(writer->get_qos()), status.last_policy_id);
}

void DdsParticipant::DiscoveryListener::Incompatible(bool local_writer, const std::string& dds_topic, const MatchTerms& local,
                                                     fdds::QosPolicyId_t policy) {
  if (!on_problem_) return;
  std::string type;  // ours: Fast DDS checks the type first, so one of another type is not it
  {
    std::lock_guard<std::mutex> lock(owner_->mutex_);
    auto it = owner_->topic_types_.find(owner_->TopicOfDds(dds_topic));
    if (it != owner_->topic_types_.end()) type = it->second;
  }
  std::vector<std::pair<std::string, std::string>> remotes;  // (name, policies) of this run's, newly found
  bool known = false;  // an incompatible remote endpoint found: ours already said, or another run's
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [guid, e] : endpoints_) {
      auto t = terms_.find(guid);
      if (e.writer == local_writer || e.topic != dds_topic || t == terms_.end() || (!type.empty() && e.type != type)) continue;
      const auto bad = local_writer ? IncompatiblePolicies(local, t->second) : IncompatiblePolicies(t->second, local);
      if (bad.empty()) continue;
      known = true;
      if (!e.same_partition || !qos_reported_.insert(guid).second) continue;
      std::string names;
      for (auto id : bad) names += (names.empty() ? "" : " and ") + QosPolicyName(id);
      remotes.emplace_back(RemoteName(e.participant), names);
    }
  }
  const std::string topic = "topic " + TopicText(dds_topic) + ": ";
  const std::string effect =
      local_writer ? "; nothing written here will reach it" : "; none of its samples will be delivered here";
  for (const auto& [name, names] : remotes)
    on_problem_(topic + (local_writer ? "a reader of " : "a writer of ") + name + (local_writer ? " requests" : " offers") +
                " an incompatible " + names + " QoS" + effect);
  // None of the remote endpoints known: one of this participant's own, or a term not modelled.
  if (remotes.empty() && !known)
    on_problem_(topic + (local_writer ? "a reader requests" : "a writer offers") + " an incompatible " + QosPolicyName(policy) +
                " QoS" + effect);
}

// "'arm/pose'", or "'arm/pose' (ROS 2 topic /arm/pose)" for one of our ROS 2 topics.
std::string DdsParticipant::DiscoveryListener::TopicText(const std::string& dds_topic) {
  std::lock_guard<std::mutex> lock(owner_->mutex_);
  const std::string topic = owner_->TopicOfDds(dds_topic);
  return topic == dds_topic ? "'" + topic + "'" : "'" + topic + "' (ROS 2 topic " + Ros2NameOfDdsTopic(dds_topic) + ")";
}

// A remote participant's name; one without (not a dyad process: another vendor's, ROS 2's)
// by its GUID prefix. REQUIRES: mutex_ held.
std::string DdsParticipant::DiscoveryListener::RemoteName(const std::string& prefix) {
  auto it = names_.find(prefix);
  if (it != names_.end() && !it->second.empty()) return "'" + it->second + "'";
  return "participant " + prefix + (it != names_.end() ? " (unnamed: not a dyad process)" : "");
}

// A ROS 2 topic (ours, or any "rt/..." that is not a dyad topic of ours) is in the default
// partition, where ROS 2 peers and our ROS 2 endpoints are.
bool DdsParticipant::DiscoveryListener::SharesPartition(const std::string& dds_topic,
                                                        const std::vector<std::string>& remote) {
  static const std::vector<std::string> kDefault;
  std::lock_guard<std::mutex> lock(owner_->mutex_);
  const std::string topic = owner_->TopicOfDds(dds_topic);
  const bool ros2 = owner_->dds_topics_.count(topic) > 0 ||
                    (!owner_->topic_types_.count(topic) && !Ros2NameOfDdsTopic(dds_topic).empty());
  return PartitionsMatch(ros2 ? kDefault : owner_->partitions_, remote);
}

void DdsParticipant::DiscoveryListener::Check(const char* kind, const std::string& dds_topic, const std::string& type,
                                              const std::string& prefix) {
  std::string ours, topic;
  {
    std::lock_guard<std::mutex> lock(owner_->mutex_);
    topic = owner_->TopicOfDds(dds_topic);
    auto it = owner_->topic_types_.find(topic);
    if (it == owner_->topic_types_.end()) return;
    ours = it->second;
  }
  if (ours == type || !on_problem_) return;
  std::string remote;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    remote = RemoteName(prefix);
  }
  const bool same_idl_name = ours.substr(0, ours.find('#')) == type.substr(0, type.find('#'));
  on_problem_("type mismatch on topic " + TopicText(dds_topic) + ": '" + owner_->name_ + "' uses " + ours + ", a " + kind + " of " +
              remote + " uses " + type +
              (same_idl_name ? " (same IDL name, different definition: rebuild both from the same idl/)"
                             : " (different types)") +
              "; no samples will flow between them");
}

// A writer of a topic this participant uses, in another run's partition: DDS does not match
// them, so nothing of it is delivered (or recorded) here; say so once per writer.
void DdsParticipant::DiscoveryListener::Foreign(const std::string& dds_topic, const std::vector<std::string>& partitions,
                                                const rtps::GUID_t& guid) {
  std::string topic;
  {
    std::lock_guard<std::mutex> lock(owner_->mutex_);
    topic = owner_->TopicOfDds(dds_topic);
    if (!owner_->topic_types_.count(topic)) return;
  }
  std::ostringstream os;
  os << guid;
  std::string remote;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!foreign_reported_.insert(os.str()).second || !on_foreign_) return;
    remote = RemoteName(GuidPrefixString(guid.guidPrefix));
  }
  on_foreign_("topic '" + topic + "' is also written by " + remote + " in " + PartitionText(partitions) +
              ", another run on this domain: ignored (not delivered, not recorded); this run is in " +
              PartitionText(owner_->partitions_));
}

void DdsParticipant::DiscoveryListener::Track(bool writer, bool gone, const std::string& topic, const std::string& type,
                                              const rtps::GUID_t& guid, bool same_partition, const MatchTerms& terms) {
  std::ostringstream os;
  os << guid;
  const std::string key = os.str();
  std::lock_guard<std::mutex> lock(mutex_);
  if (gone) {
    endpoints_.erase(key);
    terms_.erase(key);
    qos_reported_.erase(key);
    return;
  }
  endpoints_[key] = DiscoveredEndpoint{writer, topic, type, GuidPrefixString(guid.guidPrefix), key, same_partition};
  terms_[key] = terms;
}

std::vector<DiscoveredEndpoint> DdsParticipant::Discovered() const { return listener_->Snapshot(); }
size_t DdsParticipant::KnownPeerNames() const { return listener_->KnownPeers(); }

}  // namespace dyad
