// What the files of DdsParticipant (dds_participant.hpp) share; internal to runtime/dds/ (it
// brings Fast DDS's headers: no other folder includes it). The participant is one class in rooms,
// one file per concern:
//   dds_participant.cpp  its life: participant QoS (scope, network, security), its generations
//                        (participant, publishers, subscribers, topics), a participant's renewal,
//                        the order of teardown
//   dds_types.cpp        the type registry: one type per topic, registered as "name#hash" on every
//                        generation, a topic's type or DDS name refused when it changes
//   dds_endpoints.cpp    typed endpoints (DdsReader, DdsWriter): creation from TopicQos, health
//                        counts from status callbacks, their renewal and the participant's
//                        Renew/Reap/Matches
//   dds_serialized.cpp   serialized endpoints (DdsSerializedReader/Writer: CDR bytes in and out,
//                        on-demand subscriptions) and DecodeSample
//   dds_discovery.cpp    DiscoveryListener: endpoints discovered, type mismatch, incompatible QoS
//                        (whose: qos_match.hpp) and foreign-writer reports
//   dds_ros2.cpp         ROS 2 topics' endpoints: DDS topic "rt/...", their own publisher and
//                        subscriber in the default partition, and the graph's name back
//   security_qos.cpp     DDS Security's participant properties, and what a refused endpoint's
//                        error says on a secured participant
// The helpers below are the ones more than one of these files uses.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

#include "dds/dds_participant.hpp"
#include "dds/qos_match.hpp"

namespace fdds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

namespace dyad {

// Fast DDS's discovery and QoS callbacks for one DdsParticipant (all its generations); defined
// in dds_discovery.cpp, which says what it reports. Fast DDS threads call it.
class DdsParticipant::DiscoveryListener final : public fdds::DomainParticipantListener {
 public:
  DiscoveryListener(DdsParticipant* owner, ProblemHandler on_problem, ProblemHandler on_foreign)
      : owner_(owner), on_problem_(std::move(on_problem)), on_foreign_(std::move(on_foreign)) {}

  void on_participant_discovery(fdds::DomainParticipant*, rtps::ParticipantDiscoveryInfo&& info) override;
  void on_publisher_discovery(fdds::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) override;
  void on_subscriber_discovery(fdds::DomainParticipant*, rtps::ReaderDiscoveryInfo&& info) override;
  std::vector<DiscoveredEndpoint> Snapshot();
  size_t KnownPeers();
  // A secured graph's names key (dyad/wire_names.hpp): peers' opaque names are read back with it.
  // Called before the participant exists.
  void ReadNamesWith(std::string key) { names_key_ = std::move(key); }
  void CheckDiscovered(const std::string& dds_topic);
  void on_requested_incompatible_qos(fdds::DataReader* reader, const fdds::RequestedIncompatibleQosStatus& status) override;
  void on_offered_incompatible_qos(fdds::DataWriter* writer, const fdds::OfferedIncompatibleQosStatus& status) override;

 private:
  std::string TopicText(const std::string& dds_topic);
  std::string RemoteName(const std::string& prefix);  // REQUIRES: mutex_ held
  bool SharesPartition(const std::string& dds_topic, const std::vector<std::string>& remote);
  void Check(const char* kind, const std::string& dds_topic, const std::string& type, const std::string& prefix);
  void Foreign(const std::string& dds_topic, const std::vector<std::string>& partitions, const rtps::GUID_t& guid);
  void Track(bool writer, bool gone, const std::string& topic, const std::string& type, const rtps::GUID_t& guid,
             bool same_partition, const MatchTerms& terms);
  void Incompatible(bool local_writer, const std::string& dds_topic, const MatchTerms& local, fdds::QosPolicyId_t policy);

  DdsParticipant* owner_;
  ProblemHandler on_problem_, on_foreign_;
  std::mutex mutex_;
  std::set<std::string> foreign_reported_;  // writer guids
  std::map<std::string, std::string> names_;             // guid prefix -> name (read back), of peers present
  std::string names_key_;                                // "" without security
  std::map<std::string, DiscoveredEndpoint> endpoints_;  // by guid; participant holds the prefix
  std::map<std::string, MatchTerms> terms_;              // endpoints_' QoS terms, by guid
  std::set<std::string> qos_reported_;                   // guids of endpoints said incompatible
};

// Data callbacks of a renewed reader: only its current DDS entity's go through. Fast DDS holds an
// entity's lock while it calls back, and a callback takes from both entities of a renewed reader
// (the retired one first): if the retired one's callbacks ran too, two delivery threads could each
// hold one entity's lock and wait for the other's. So a retired entity's callbacks are dropped
// (its samples are taken with the current one's), and a renewal waits out the ones already
// running before it hands out the second entity (two epochs of in-flight counts, as RCU does).
class CallbackGate {
 public:
  // True: the callback may run; call Leave(ticket) after it.
  bool Enter(const fdds::DataReader* entity, uint64_t* ticket) {
    if (entity != current_.load()) return false;
    const uint64_t epoch = epoch_.load();
    in_flight_[epoch & 1].fetch_add(1);
    if (epoch_.load() != epoch || entity != current_.load()) {  // renewed meanwhile
      in_flight_[epoch & 1].fetch_sub(1);
      return false;
    }
    *ticket = epoch;
    return true;
  }
  void Leave(uint64_t ticket) { in_flight_[ticket & 1].fetch_sub(1); }
  bool IsCurrent(const fdds::DataReader* entity) const { return entity == current_.load(); }
  // From now on only `entity` calls back; waits (2 s at most) for the callbacks that entered
  // before. The thread calling it must not hold anything a callback waits for.
  void SetCurrent(const fdds::DataReader* entity) {
    current_.store(entity);
    const uint64_t old = epoch_.fetch_add(1);
    for (int i = 0; i < 2000 && in_flight_[old & 1].load() > 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }

 private:
  std::atomic<const fdds::DataReader*> current_{nullptr};
  std::atomic<uint64_t> epoch_{0};
  std::atomic<int> in_flight_[2] = {0, 0};
};

// Endpoints' helpers (defined in dds_endpoints.cpp unless inline here).

// The sample's writer and number, for SeenWriters; a sample with no known writer is always fresh.
// The GUID's two parts are copied with memcpy of their fixed sizes, which the compiler turns into
// two moves (std::copy here compiled to two calls of memcpy: 160 instructions per bench_pingpong
// round trip).
inline bool FreshSample(SeenWriters& seen, const fdds::SampleInfo& info) {
  const rtps::GUID_t& g = info.sample_identity.writer_guid();
  if (g == rtps::GUID_t::unknown()) return true;
  SeenWriters::Guid key;
  static_assert(sizeof(g.guidPrefix.value) + sizeof(g.entityId.value) == sizeof(key));
  std::memcpy(key.data(), g.guidPrefix.value, sizeof(g.guidPrefix.value));
  std::memcpy(key.data() + sizeof(g.guidPrefix.value), g.entityId.value, sizeof(g.entityId.value));
  return seen.Fresh(key, info.sample_identity.sequence_number().to64long());
}

// A DDS time from a runtime stamp (negative: 0).
inline eprosima::fastrtps::Time_t TimeOfNs(int64_t ns) {
  if (ns < 0) ns = 0;
  return eprosima::fastrtps::Time_t(static_cast<int32_t>(ns / 1'000'000'000), static_cast<uint32_t>(ns % 1'000'000'000));
}

// How many endpoints a DDS reader (0 for none) or writer is matched with now.
int ReaderMatched(fdds::DataReader* r);
int WriterMatched(fdds::DataWriter* w);
// Whether a reader retired at `since` may go (see kRetireS).
bool RetiredDone(fdds::DataReader* retired, std::chrono::steady_clock::time_point since);
// Waits up to 0.5 s for a reliable writer's samples to be acknowledged (before it is deleted).
void AwaitAcks(fdds::DataWriter* w);
// Deletes an entity through the publisher or subscriber that made it (nullptr: nothing).
void DeleteReader(fdds::DataReader* d);
void DeleteWriter(fdds::DataWriter* d);
// A guest's (kWatcher's) writer keeps enough history for readers that match it late.
void KeepForLateMatches(fdds::DataWriterQos& q);

// A topic's TopicQos on a DDS reader's or writer's QoS.
template <class Q>
void ApplyQos(Q& q, const TopicQos& qos) {
  q.reliability().kind = qos.reliability == Reliability::kReliable ? fdds::RELIABLE_RELIABILITY_QOS : fdds::BEST_EFFORT_RELIABILITY_QOS;
  q.durability().kind = qos.transient_local ? fdds::TRANSIENT_LOCAL_DURABILITY_QOS : fdds::VOLATILE_DURABILITY_QOS;
  if (qos.keep_all) {
    q.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  } else {
    q.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
    q.history().depth = qos.depth;
  }
  if (qos.deadline_ms > 0) q.deadline().period = eprosima::fastrtps::Duration_t(qos.deadline_ms * 1e-3);
  if (qos.liveliness_ms > 0) {
    q.liveliness().kind = fdds::AUTOMATIC_LIVELINESS_QOS;
    q.liveliness().lease_duration = eprosima::fastrtps::Duration_t(qos.liveliness_ms * 1e-3);
    q.liveliness().announcement_period = eprosima::fastrtps::Duration_t(qos.liveliness_ms * 1e-3 / 3);
  }
}

}  // namespace dyad
