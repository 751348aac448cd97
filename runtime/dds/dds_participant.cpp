#include "dds/dds_participant.hpp"

#include "dds/network_qos.hpp"
#include "dds/security_qos.hpp"

#include <dyad/decode_sample.hpp>
#include <dyad/ros2_names.hpp>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/builtin/data/ParticipantProxyData.h>
#include <fastdds/rtps/builtin/data/ReaderProxyData.h>
#include <fastdds/rtps/builtin/data/WriterProxyData.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>

#include <fnmatch.h>

#include <algorithm>
#include <set>
#include <shared_mutex>
#include <thread>
#include <sstream>

namespace fdds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

namespace dyad {
namespace {

std::string GuidPrefixString(const rtps::GuidPrefix_t& p) {
  std::ostringstream os;
  os << p;
  return os.str();
}

std::string QosPolicyName(fdds::QosPolicyId_t id) {
  switch (id) {
    case fdds::RELIABILITY_QOS_POLICY_ID: return "reliability";
    case fdds::DURABILITY_QOS_POLICY_ID: return "durability";
    case fdds::DEADLINE_QOS_POLICY_ID: return "deadline";
    case fdds::HISTORY_QOS_POLICY_ID: return "history";
    default: return "policy " + std::to_string(static_cast<int>(id));
  }
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

class DdsParticipant::DiscoveryListener final : public fdds::DomainParticipantListener {
 public:
  DiscoveryListener(DdsParticipant* owner, ProblemHandler on_problem, ProblemHandler on_foreign)
      : owner_(owner), on_problem_(std::move(on_problem)), on_foreign_(std::move(on_foreign)) {}

  void on_participant_discovery(fdds::DomainParticipant*, rtps::ParticipantDiscoveryInfo&& info) override {
    std::lock_guard<std::mutex> lock(mutex_);
    names_[GuidPrefixString(info.info.m_guid.guidPrefix)] = info.info.m_participantName.to_string();
  }
  // Remote endpoints are named by their DDS topic; ours by the graph's topic (a ROS 2 topic's
  // DDS topic is "rt/...", in the default partition): compare in the graph's names.
  void on_publisher_discovery(fdds::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) override {
    const bool gone = info.status == rtps::WriterDiscoveryInfo::REMOVED_WRITER;
    const std::string dds_topic = info.info.topicName().to_string();
    const bool same_partition = SharesPartition(dds_topic, info.info.m_qos.m_partition.names());
    Track(true, gone, dds_topic, info.info.typeName().to_string(), info.info.guid(), same_partition);
    if (info.status != rtps::WriterDiscoveryInfo::DISCOVERED_WRITER) return;
    if (!same_partition) {
      Foreign(dds_topic, info.info.m_qos.m_partition.names(), info.info.guid());
      return;  // another run's: its type is not ours to check
    }
    Check("writer", dds_topic, info.info.typeName().to_string(), GuidPrefixString(info.info.guid().guidPrefix));
  }
  void on_subscriber_discovery(fdds::DomainParticipant*, rtps::ReaderDiscoveryInfo&& info) override {
    const bool gone = info.status == rtps::ReaderDiscoveryInfo::REMOVED_READER;
    const std::string dds_topic = info.info.topicName().to_string();
    const bool same_partition = SharesPartition(dds_topic, info.info.m_qos.m_partition.names());
    Track(false, gone, dds_topic, info.info.typeName().to_string(), info.info.guid(), same_partition);
    if (info.status != rtps::ReaderDiscoveryInfo::DISCOVERED_READER) return;
    if (!same_partition) return;
    Check("reader", dds_topic, info.info.typeName().to_string(), GuidPrefixString(info.info.guid().guidPrefix));
  }

  // Endpoints by the names this participant uses: a ROS 2 topic of ours by its graph name, any
  // other ROS 2 topic by its ROS 2 name ("rt/a/b" -> "/a/b").
  std::vector<DiscoveredEndpoint> Snapshot() {
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
  void CheckDiscovered(const std::string& dds_topic) {
    std::vector<DiscoveredEndpoint> known;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const auto& [guid, e] : endpoints_)
        if (e.topic == dds_topic && e.same_partition) known.push_back(e);
    }
    for (const auto& e : known) Check(e.writer ? "writer" : "reader", dds_topic, e.type, e.participant);
  }
  void on_requested_incompatible_qos(fdds::DataReader* reader, const fdds::RequestedIncompatibleQosStatus& status) override {
    if (on_problem_)
      on_problem_("topic " + TopicText(reader->get_topicdescription()->get_name()) + ": a writer offers an incompatible " +
                  QosPolicyName(status.last_policy_id) + " QoS; no data will flow to this reader");
  }
  void on_offered_incompatible_qos(fdds::DataWriter* writer, const fdds::OfferedIncompatibleQosStatus& status) override {
    if (on_problem_)
      on_problem_("topic " + TopicText(writer->get_topic()->get_name()) + ": a reader requests an incompatible " +
                  QosPolicyName(status.last_policy_id) + " QoS; this writer's data will not reach it");
  }

 private:
  // A ROS 2 topic (ours, or any "rt/..." that is not a dyad topic of ours) is in the default
  // partition, where ROS 2 peers and our ROS 2 endpoints are.
  // "'arm/pose'", or "'arm/pose' (ROS 2 topic /arm/pose)" for one of our ROS 2 topics.
  std::string TopicText(const std::string& dds_topic) {
    std::lock_guard<std::mutex> lock(owner_->mutex_);
    const std::string topic = owner_->TopicOfDds(dds_topic);
    return topic == dds_topic ? "'" + topic + "'" : "'" + topic + "' (ROS 2 topic " + Ros2NameOfDdsTopic(dds_topic) + ")";
  }
  // A remote participant's name; one without (not a dyad process: another vendor's, ROS 2's)
  // by its GUID prefix. REQUIRES: mutex_ held.
  std::string RemoteName(const std::string& prefix) {
    auto it = names_.find(prefix);
    if (it != names_.end() && !it->second.empty()) return "'" + it->second + "'";
    return "participant " + prefix + (it != names_.end() ? " (unnamed: not a dyad process)" : "");
  }



  bool SharesPartition(const std::string& dds_topic, const std::vector<std::string>& remote) {
    static const std::vector<std::string> kDefault;
    std::lock_guard<std::mutex> lock(owner_->mutex_);
    const std::string topic = owner_->TopicOfDds(dds_topic);
    const bool ros2 = owner_->dds_topics_.count(topic) > 0 ||
                      (!owner_->topic_types_.count(topic) && !Ros2NameOfDdsTopic(dds_topic).empty());
    return PartitionsMatch(ros2 ? kDefault : owner_->partitions_, remote);
  }

  void Check(const char* kind, const std::string& dds_topic, const std::string& type, const std::string& prefix) {
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
  void Foreign(const std::string& dds_topic, const std::vector<std::string>& partitions, const rtps::GUID_t& guid) {
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

  void Track(bool writer, bool gone, const std::string& topic, const std::string& type, const rtps::GUID_t& guid,
             bool same_partition) {
    std::ostringstream os;
    os << guid;
    std::lock_guard<std::mutex> lock(mutex_);
    if (gone) {
      endpoints_.erase(os.str());
      return;
    }
    endpoints_[os.str()] = DiscoveredEndpoint{writer, topic, type, GuidPrefixString(guid.guidPrefix), os.str(), same_partition};
  }

  DdsParticipant* owner_;
  ProblemHandler on_problem_, on_foreign_;
  std::mutex mutex_;
  std::set<std::string> foreign_reported_;  // writer guids
  std::map<std::string, std::string> names_;  // guid prefix -> participant name
  std::map<std::string, DiscoveredEndpoint> endpoints_;  // by guid; participant holds the prefix
};

std::vector<DiscoveredEndpoint> DdsParticipant::Discovered() const { return listener_->Snapshot(); }

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

// Health counters are kept from Fast DDS's status callbacks (its threads) and read by the
// component's poll: atomics.
class DdsReader::Listener final : public fdds::DataReaderListener {
 public:
  Listener(std::function<void()> on_data, bool liveliness) : on_data_(std::move(on_data)), liveliness_(liveliness) {}
  void on_data_available(fdds::DataReader* r) override {
    uint64_t ticket = 0;
    if (!on_data_ || !gate_.Enter(r, &ticket)) return;
    on_data_();
    gate_.Leave(ticket);
  }
  // Status callbacks count for the current DDS reader only (a retired one is going away).
  void on_subscription_matched(fdds::DataReader* r, const fdds::SubscriptionMatchedStatus& s) override {
    if (gate_.IsCurrent(r)) matched_.store(s.current_count, std::memory_order_relaxed);
  }
  void on_liveliness_changed(fdds::DataReader* r, const fdds::LivelinessChangedStatus& s) override {
    if (gate_.IsCurrent(r)) alive_.store(s.alive_count, std::memory_order_relaxed);
  }
  void on_requested_deadline_missed(fdds::DataReader*, const fdds::RequestedDeadlineMissedStatus&) override {
    deadline_misses_.fetch_add(1, std::memory_order_relaxed);
  }
  // The DDS reader whose callbacks and status count (set before it can call back, and on
  // renewal: see CallbackGate, whose wait this includes).
  void SetCurrent(fdds::DataReader* r) {
    gate_.SetCurrent(r);
    if (r == nullptr) return;
    fdds::SubscriptionMatchedStatus m;
    r->get_subscription_matched_status(m);
    matched_.store(m.current_count, std::memory_order_relaxed);
    fdds::LivelinessChangedStatus l;
    r->get_liveliness_changed_status(l);
    alive_.store(l.alive_count, std::memory_order_relaxed);
  }
  // With a liveliness lease the alive count is the truth; without, a writer counts while matched
  // (the participant lease ends the match of a writer whose process died).
  int alive_writers() const {
    const int matched = matched_.load(std::memory_order_relaxed);
    return liveliness_ ? std::min(matched, alive_.load(std::memory_order_relaxed)) : matched;
  }
  uint64_t deadline_misses() const { return deadline_misses_.load(std::memory_order_relaxed); }
  int matched() const { return matched_.load(std::memory_order_relaxed); }

 private:
  std::function<void()> on_data_;
  bool liveliness_;
  CallbackGate gate_;
  std::atomic<int> matched_{0}, alive_{0};
  std::atomic<uint64_t> deadline_misses_{0};
};

bool SeenWriters::Fresh(const Guid& writer, int64_t sequence) {
  for (auto& [guid, newest] : seen_) {
    if (guid != writer) continue;
    if (sequence <= newest) return false;
    newest = sequence;
    return true;
  }
  seen_.emplace_back(writer, sequence);
  return true;
}

namespace {
// The sample's writer and number, for SeenWriters; a sample with no known writer is always fresh.
bool FreshSample(SeenWriters& seen, const fdds::SampleInfo& info) {
  const rtps::GUID_t& g = info.sample_identity.writer_guid();
  if (g == rtps::GUID_t::unknown()) return true;
  SeenWriters::Guid key;
  std::copy(g.guidPrefix.value, g.guidPrefix.value + 12, key.begin());
  std::copy(g.entityId.value, g.entityId.value + 4, key.begin() + 12);
  return seen.Fresh(key, info.sample_identity.sequence_number().to64long());
}

int ReaderMatched(fdds::DataReader* r) {
  if (r == nullptr) return 0;
  fdds::SubscriptionMatchedStatus st;
  r->get_subscription_matched_status(st);
  return st.current_count;
}

int WriterMatched(fdds::DataWriter* w) {
  fdds::PublicationMatchedStatus st;
  w->get_publication_matched_status(st);
  return st.current_count;
}

// A retired reader is kept kRetireS, not just until its successor has matched: the reader side
// matching a writer does not mean the writer has matched the new reader yet (each side learns the
// other on its own), and until it has, the retired reader is the only one receiving its samples.
bool RetiredDone(fdds::DataReader* retired, std::chrono::steady_clock::time_point since) {
  const auto age = std::chrono::steady_clock::now() - since;
  if (age > std::chrono::duration<double>(2 * kRetireS)) return true;  // unread samples nobody takes
  return age > std::chrono::duration<double>(kRetireS) && retired->get_unread_count() == 0;
}
}  // namespace

int DdsReader::AliveWriters() const { return listener_->alive_writers(); }
uint64_t DdsReader::DeadlineMisses() const { return listener_->deadline_misses(); }

DdsReader::~DdsReader() {
  if (!destroy_) return;
  for (fdds::DataReader* d : graveyard_) destroy_(d);
  destroy_(retired_);
  destroy_(reader_);
}

bool DdsReader::TakeNext(void* sample) {
  std::shared_lock<std::shared_mutex> lock(entities_);
  fdds::SampleInfo info;
  for (fdds::DataReader* r : {retired_, reader_}) {  // the retired one's samples are older
    if (r == nullptr) continue;
    while (r->take_next_sample(sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      std::lock_guard<std::mutex> seen(seen_mutex_);
      if (FreshSample(seen_, info)) return true;
    }
  }
  return false;
}

uint64_t DdsReader::Unread() const {
  std::shared_lock<std::shared_mutex> lock(entities_);
  return reader_->get_unread_count() + (retired_ != nullptr ? retired_->get_unread_count() : 0);
}

int DdsReader::Matched() const { return listener_->matched(); }

bool DdsReader::Renew() {
  {
    std::shared_lock<std::shared_mutex> lock(entities_);
    if (retired_ != nullptr) return false;  // one renewal at a time: its retired reader may hold samples
  }
  fdds::DataReader* fresh = make_();  // counted by the listener from now on
  if (fresh == nullptr) return false;
  std::unique_lock<std::shared_mutex> lock(entities_);
  retired_ = reader_;
  reader_ = fresh;
  retired_at_ = std::chrono::steady_clock::now();
  return true;
}

bool DdsReader::Reap(bool force) {
  {
    std::shared_lock<std::shared_mutex> lock(entities_);
    if (retired_ == nullptr) return true;
    if (!force && !RetiredDone(retired_, retired_at_)) return false;
  }
  std::unique_lock<std::shared_mutex> lock(entities_);
  graveyard_.push_back(std::exchange(retired_, nullptr));  // deleted with this reader (kRetireS)
  return true;
}

namespace {
// A reliable writer deleted with samples in flight loses them for remote readers (a recorder in
// another process): give acknowledgments a moment first. Returns at once when all are acked,
// when nothing matched, or for best-effort writers.
void AwaitAcks(fdds::DataWriter* w) {
  if (w != nullptr) w->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(0.5));
}
}  // namespace

bool DdsWriter::AwaitAcknowledged(double timeout_s) {
  std::shared_lock<std::shared_mutex> lock(entities_);
  return writer_->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(timeout_s)) == ReturnCode_t::RETCODE_OK;
}

DdsWriter::~DdsWriter() {
  AwaitAcks(writer_);
  if (destroy_) destroy_(writer_);
}

bool DdsWriter::Renew() {
  fdds::DataWriter* fresh = make_();
  if (fresh == nullptr) return false;
  fdds::DataWriter* old = nullptr;
  {
    std::unique_lock<std::shared_mutex> lock(entities_);
    old = std::exchange(writer_, fresh);
  }
  destroy_(old);
  return true;
}

Status DdsWriter::Write(const void* sample) {
  std::shared_lock<std::shared_mutex> lock(entities_);
  if (!writer_->write(const_cast<void*>(sample)))
    return Status::IOError("topic '" + topic_ + "': DDS write failed");
  return Status::OK();
}

namespace {
eprosima::fastrtps::Time_t TimeOfNs(int64_t ns) {
  if (ns < 0) ns = 0;
  return eprosima::fastrtps::Time_t(static_cast<int32_t>(ns / 1'000'000'000), static_cast<uint32_t>(ns % 1'000'000'000));
}
}  // namespace

Status DdsWriter::WriteStamped(const void* sample, int64_t stamp_ns) {
  std::shared_lock<std::shared_mutex> lock(entities_);
  if (writer_->write_w_timestamp(const_cast<void*>(sample), fdds::HANDLE_NIL, TimeOfNs(stamp_ns)) != ReturnCode_t::RETCODE_OK)
    return Status::IOError("topic '" + topic_ + "': DDS write failed");
  return Status::OK();
}

// A serialized reader's listener: its samples, and its matches (EndpointHealth).
const fdds::StatusMask kSerializedMask = fdds::StatusMask::data_available() << fdds::StatusMask::subscription_matched();
// A stopped on-demand reader's: its matches only (nothing is taken, so nothing is decoded).
const fdds::StatusMask kStoppedMask = fdds::StatusMask::subscription_matched();

// What a serialized endpoint reuses for every sample: its own (unregistered) type support for
// (de)serialising, one sample object and one payload buffer.
struct SerializedScratch {
  explicit SerializedScratch(const TypeInfo& type) : support(type.make_type_support()) {
    sample = support->createData();
    payload.reserve(support->m_typeSize + 64);
  }
  ~SerializedScratch() {
    if (sample) support->deleteData(sample);
  }
  fdds::TypeSupport support;
  void* sample = nullptr;
  eprosima::fastrtps::rtps::SerializedPayload_t payload;
};

// Decodes `cdr` into `sample` through `support`, copying the bytes into `payload` (grown as
// needed). False when they do not decode (fastcdr throws on short input: nothing escapes).
static bool DecodeInto(fdds::TopicDataType& support, eprosima::fastrtps::rtps::SerializedPayload_t& payload,
                       std::span<const uint8_t> cdr, void* sample) {
  if (cdr.size() > UINT32_MAX) return false;
  if (payload.max_size < cdr.size()) payload.reserve(static_cast<uint32_t>(cdr.size()));
  std::copy(cdr.begin(), cdr.end(), payload.data);
  payload.length = static_cast<uint32_t>(cdr.size());
  payload.pos = 0;
  try {
    return support.deserialize(&payload, sample);
  } catch (...) {
    return false;
  }
}

struct DdsSerializedReader::Scratch : SerializedScratch {
  using SerializedScratch::SerializedScratch;
};
struct DdsSerializedWriter::Scratch : SerializedScratch {
  using SerializedScratch::SerializedScratch;
};

class DdsSerializedReader::Listener final : public fdds::DataReaderListener {
 public:
  explicit Listener(DdsSerializedReader* owner) : owner_(owner) {}
  void on_data_available(fdds::DataReader* r) override {
    uint64_t ticket = 0;
    if (!gate_.Enter(r, &ticket)) return;
    {
      std::lock_guard<std::mutex> lock(owner_->mutex_);
      if (!owner_->closed_) owner_->Drain();
    }
    gate_.Leave(ticket);
  }
  void on_subscription_matched(fdds::DataReader* r, const fdds::SubscriptionMatchedStatus& s) override {
    if (gate_.IsCurrent(r)) matched_.store(s.current_count, std::memory_order_relaxed);
  }
  // The DDS reader whose callbacks and matches count (before its listener is attached, and on
  // renewal: see CallbackGate, whose wait this includes).
  void SetCurrent(fdds::DataReader* r) {
    gate_.SetCurrent(r);
    matched_.store(ReaderMatched(r), std::memory_order_relaxed);
  }
  int matched() const { return matched_.load(std::memory_order_relaxed); }

 private:
  DdsSerializedReader* owner_;
  CallbackGate gate_;
  std::atomic<int> matched_{0};
};

DdsSerializedReader::DdsSerializedReader() = default;
DdsSerializedReader::~DdsSerializedReader() {
  Close();
  if (!destroy_) return;
  for (fdds::DataReader* d : graveyard_) destroy_(d);
  destroy_(retired_);
  destroy_(reader_);
}

void DdsSerializedReader::Close() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (closed_) return;
  Drain();
  closed_ = true;
}

Status DdsSerializedReader::Start() {
  std::lock_guard<std::mutex> entity(entity_mutex_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return Status::FailedPrecondition("topic '" + topic_ + "': subscription closed (the run is stopping)");
    if (started_) return Status::OK();
  }
  if (!exists()) {
    // The listener is attached below, once the reader is in place (as at creation).
    fdds::DataReader* fresh = make_();
    if (fresh == nullptr) return Status::Internal("cannot create reader on topic '" + topic_ + "'");
    listener_->SetCurrent(fresh);
    std::lock_guard<std::mutex> lock(mutex_);
    reader_ = fresh;
    exists_.store(true, std::memory_order_release);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    started_ = true;
  }
  // reader_ changes under entity_mutex_ only, which this thread holds.
  reader_->set_listener(listener_.get(), kSerializedMask);
  std::lock_guard<std::mutex> lock(mutex_);
  if (!closed_) Drain();  // what the history kept, and what came before the listener
  return Status::OK();
}

void DdsSerializedReader::Stop() {
  std::lock_guard<std::mutex> entity(entity_mutex_);
  {
    std::lock_guard<std::mutex> lock(mutex_);  // waits for a running callback
    if (!started_) return;
    started_ = false;
  }
  // Samples still arrive into the KEEP_LAST history, replacing older ones; none is taken.
  if (reader_ != nullptr) reader_->set_listener(listener_.get(), kStoppedMask);
}

bool DdsSerializedReader::started() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return started_;
}

int DdsSerializedReader::Matched() const { return listener_->matched(); }

bool DdsSerializedReader::Renew() {
  std::lock_guard<std::mutex> entity(entity_mutex_);
  bool started = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (retired_ != nullptr || closed_ || reader_ == nullptr) return false;  // one renewal at a time; none before Start()
    started = started_;
  }
  fdds::DataReader* fresh = make_();
  if (fresh == nullptr) return false;
  listener_->SetCurrent(fresh);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    Drain();
    retired_ = reader_;
    reader_ = fresh;
    retired_at_ = std::chrono::steady_clock::now();
  }
  fresh->set_listener(listener_.get(), started ? kSerializedMask : kStoppedMask);
  std::lock_guard<std::mutex> lock(mutex_);
  if (!closed_) Drain();
  return true;
}

bool DdsSerializedReader::Reap(bool force) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (retired_ == nullptr) return true;
    if (!force && !RetiredDone(retired_, retired_at_)) return false;
    if (!closed_ && started_) Drain(retired_);
    graveyard_.push_back(std::exchange(retired_, nullptr));  // drained, deleted with this reader (kRetireS)
  }
  return true;
}

void DdsSerializedReader::Drain() {
  if (!started_ || reader_ == nullptr) return;  // stopped: the KEEP_LAST history holds what comes
  for (fdds::DataReader* d : graveyard_) Drain(d);  // KEEP_ALL: what still reaches them must not pile up
  if (retired_ != nullptr) Drain(retired_);  // its samples are older
  Drain(reader_);
}

void DdsSerializedReader::Drain(fdds::DataReader* reader) {
  Scratch& s = *scratch_;
  fdds::SampleInfo info;
  while (reader->take_next_sample(s.sample, &info) == ReturnCode_t::RETCODE_OK) {
    if (!info.valid_data || !FreshSample(seen_, info)) continue;
    const uint32_t need = s.support->getSerializedSizeProvider(s.sample)();
    if (s.payload.max_size < need) s.payload.reserve(need);
    s.payload.length = 0;
    s.payload.pos = 0;
    if (!s.support->serialize(s.sample, &s.payload)) continue;  // cannot happen for a sample we just decoded
    SerializedSample out;
    out.cdr = std::span<const uint8_t>(s.payload.data, s.payload.length);
    out.source_stamp_ns = info.source_timestamp.to_ns();
    out.receive_ns = clock_->now_ns();
    out.sequence = info.sample_identity.sequence_number().to64long();
    callback_(out);
    delivered_.fetch_add(1, std::memory_order_relaxed);
  }
}

DdsSerializedWriter::DdsSerializedWriter() = default;
DdsSerializedWriter::~DdsSerializedWriter() {
  AwaitAcks(writer_);
  if (destroy_) destroy_(writer_);
}

bool DdsSerializedWriter::Renew() {
  fdds::DataWriter* fresh = make_();
  if (fresh == nullptr) return false;
  fdds::DataWriter* old = nullptr;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    old = std::exchange(writer_, fresh);
  }
  destroy_(old);
  return true;
}

Status DdsSerializedWriter::Write(std::span<const uint8_t> cdr, int64_t source_stamp_ns) {
  std::lock_guard<std::mutex> lock(mutex_);
  Scratch& s = *scratch_;
  if (cdr.size() > UINT32_MAX) return Status::InvalidArgument("topic '" + topic_ + "': sample of " + std::to_string(cdr.size()) + " bytes is too large");
  if (!DecodeInto(*s.support, s.payload, cdr, s.sample))
    return Status::InvalidArgument("topic '" + topic_ + "': " + std::to_string(cdr.size()) + " bytes do not decode as " + type_->name);
  const int64_t stamp = source_stamp_ns >= 0 ? source_stamp_ns : clock_->now_ns();
  if (writer_->write_w_timestamp(s.sample, fdds::HANDLE_NIL, TimeOfNs(stamp)) != ReturnCode_t::RETCODE_OK)
    return Status::IOError("topic '" + topic_ + "': DDS write failed");
  ++written_;
  return Status::OK();
}

Status DecodeSample(std::span<const uint8_t> cdr, const TypeInfo& type, void* sample) {
  std::unique_ptr<fdds::TopicDataType> support(type.make_type_support());
  eprosima::fastrtps::rtps::SerializedPayload_t payload;
  if (!DecodeInto(*support, payload, cdr, sample))
    return Status::InvalidArgument(std::to_string(cdr.size()) + " bytes do not decode as " + type.name);
  return Status::OK();
}

int DdsWriter::matched() const {
  std::shared_lock<std::shared_mutex> lock(entities_);
  return WriterMatched(writer_);
}

StatusOr<std::unique_ptr<DdsParticipant>> DdsParticipant::Create(int domain_id, const std::string& name, Options options) {
  const Scope scope = options.scope;
  const NetworkConfig& network = options.network;
  const std::string& process = options.process;
  std::unique_ptr<DdsParticipant> p(new DdsParticipant());
  p->name_ = name;
  p->partitions_ = options.partitions;
  p->listener_ = std::make_unique<DiscoveryListener>(p.get(), std::move(options.on_problem), std::move(options.on_foreign_writer));
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  factory->load_profiles();  // profiles load lazily; load them before reading defaults
  fdds::DomainParticipantQos qos = factory->get_default_participant_qos();
  qos.name(name);
  p->scope_ = scope;
  p->secured_ = options.security.enabled();
  ApplySecurity(options.security, &qos);
  // A stepped run stays inside its process: the network section does not concern it.
  if (scope != Scope::kProcessOnly)
    if (Status s = ApplyNetwork(network, scope == Scope::kWatcher, &qos, process); !s.ok()) return s;
  if (scope == Scope::kWatcher) {
    // A watcher lives seconds: announce often, so a first discovery exchange that got lost is
    // repeated within half a second rather than the default 3 s.
    qos.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod = eprosima::fastrtps::Duration_t(0.5);
  }
  if (scope == Scope::kProcessOnly) {
    // Discovery ignores participants of other processes: nothing matches across the process
    // boundary, while this participant's own endpoints match and deliver intra-process.
    qos.wire_protocol().builtin.discovery_config.ignoreParticipantFlags =
        eprosima::fastrtps::rtps::ParticipantFilteringFlags_t::FILTER_DIFFERENT_PROCESS;
  }
  p->domain_id_ = domain_id;
  p->network_ = network;
  p->qos_ = std::make_unique<fdds::DomainParticipantQos>(qos);
  auto g = p->MakeGeneration();
  if (!g.ok()) return g.status();
  p->gen_ = g.value();
  return p;
}

std::string DdsParticipant::SecurityHint(const std::string& verb) const {
  if (!secured_) return "";
  return " (DDS Security: the permissions of participant '" + name_ + "' do not let it " + verb +
         " this topic; after changing the graph, rerun `dyad security init`)";
}

StatusOr<DdsParticipant::Generation> DdsParticipant::MakeGeneration() {
  fdds::StatusMask mask = fdds::StatusMask::none();
  mask << fdds::StatusMask::requested_incompatible_qos() << fdds::StatusMask::offered_incompatible_qos();
  Generation g;
  g.participant = fdds::DomainParticipantFactory::get_instance()->create_participant(domain_id_, *qos_, listener_.get(), mask);
  if (g.participant == nullptr)
    return Status::Internal("cannot create DDS participant '" + name_ + "' on domain " + std::to_string(domain_id_) +
                            (secured_ ? " (DDS Security refused its identity or documents: Fast DDS's log above says why; "
                                        "`dyad validate` checks the keystore)"
                                      : ""));
  fdds::PublisherQos pub_qos = fdds::PUBLISHER_QOS_DEFAULT;
  fdds::SubscriberQos sub_qos = fdds::SUBSCRIBER_QOS_DEFAULT;
  for (const auto& partition : partitions_) {
    pub_qos.partition().push_back(partition.c_str());
    sub_qos.partition().push_back(partition.c_str());
  }
  g.publisher = g.participant->create_publisher(pub_qos);
  g.subscriber = g.participant->create_subscriber(sub_qos);
  g.ros2_publisher = g.participant->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
  g.ros2_subscriber = g.participant->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  Status st = g.publisher != nullptr && g.subscriber != nullptr && g.ros2_publisher != nullptr && g.ros2_subscriber != nullptr
                  ? Status::OK()
                  : Status::Internal("cannot create DDS publisher/subscriber for '" + name_ + "'");
  // The topics of the generation it replaces (a renewal), with their types.
  for (const auto& [topic, type] : topic_infos_) {
    if (!st.ok()) break;
    auto dds = dds_topics_.find(topic);
    st = AddTopic(g, topic, dds == dds_topics_.end() ? topic : dds->second, *type);
  }
  if (!st.ok()) {
    DeleteGeneration(g);
    return st;
  }
  return g;
}

Status DdsParticipant::AddTopic(Generation& g, const std::string& topic, const std::string& dds_topic, const TypeInfo& type) {
  const std::string dds_type = type.dds_name();
  if (g.participant->find_type(dds_type).empty()) {
    fdds::TypeSupport support(type.make_type_support());
    if (support.register_type(g.participant, dds_type) != ReturnCode_t::RETCODE_OK)
      return Status::Internal("cannot register type " + dds_type);
  }
  fdds::Topic* t = g.participant->create_topic(dds_topic, dds_type, fdds::TOPIC_QOS_DEFAULT);
  if (t == nullptr) return Status::Internal("cannot create topic '" + dds_topic + "' of type " + dds_type);
  g.topics[topic] = t;
  return Status::OK();
}

std::string DdsParticipant::TopicOfDds(const std::string& dds_topic) const {
  auto it = ros2_topics_.find(dds_topic);
  return it == ros2_topics_.end() ? dds_topic : it->second;
}


void DdsParticipant::DeleteGeneration(Generation& g) {
  if (g.participant == nullptr) return;
  g.participant->set_listener(nullptr);
  g.participant->delete_contained_entities();
  fdds::DomainParticipantFactory::get_instance()->delete_participant(g.participant);
  g = Generation{};
}

// Not under mutex_: creating an endpoint calls the discovery listener back, which takes it.
// (Generations are swapped and deleted on the executor's thread, which is the one calling.)
fdds::DataReader* DdsParticipant::NewReader(const std::string& topic, const fdds::DataReaderQos& qos) {
  fdds::Subscriber* sub = nullptr;
  fdds::Topic* t = nullptr;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    sub = dds_topics_.count(topic) ? gen_.ros2_subscriber : gen_.subscriber;
    t = gen_.topics.at(topic);
  }
  return sub->create_datareader(t, qos, nullptr, fdds::StatusMask::none());
}

fdds::DataWriter* DdsParticipant::NewWriter(const std::string& topic, const fdds::DataWriterQos& qos) {
  fdds::Publisher* pub = nullptr;
  fdds::Topic* t = nullptr;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pub = dds_topics_.count(topic) ? gen_.ros2_publisher : gen_.publisher;
    t = gen_.topics.at(topic);
  }
  return pub->create_datawriter(t, qos);
}

namespace {
// An entity goes with the publisher or subscriber (of whichever generation) that made it.
void DeleteReader(fdds::DataReader* d) {
  if (d == nullptr) return;
  d->set_listener(nullptr);
  const_cast<fdds::Subscriber*>(d->get_subscriber())->delete_datareader(d);
}
void DeleteWriter(fdds::DataWriter* d) {
  if (d != nullptr) const_cast<fdds::Publisher*>(d->get_publisher())->delete_datawriter(d);
}
}  // namespace

bool DdsParticipant::RenewParticipant() {
  if (scope_ != Scope::kProcessOnly && !NetworkUp(network_)) return false;  // it would announce loopback only
  auto g = MakeGeneration();
  if (!g.ok()) return false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    retired_gens_.push_back(gen_);
    gen_ = g.value();
  }
  // Every endpoint onto the new participant; a reader's renewal in flight ends first.
  for (auto& r : readers_) {
    r->Reap(true);
    r->Renew();
  }
  for (auto& r : serialized_readers_) {
    r->Reap(true);
    r->Renew();
  }
  for (auto& w : writers_) w->Renew();
  for (auto& w : serialized_writers_) w->Renew();
  return true;
}

std::vector<EndpointMatch> DdsParticipant::Matches() const {
  std::vector<EndpointMatch> out;
  for (const auto& w : writers_) out.push_back({w->topic_, true, false, w->matched()});
  for (const auto& w : serialized_writers_) {
    std::lock_guard<std::mutex> lock(w->mutex_);
    out.push_back({w->topic_, true, true, WriterMatched(w->writer_)});
  }
  for (const auto& r : readers_) out.push_back({r->topic_, false, false, r->Matched()});
  for (const auto& r : serialized_readers_)
    if (r->exists()) out.push_back({r->topic_, false, true, r->Matched()});  // not an on-demand one never started
  return out;
}

int DdsParticipant::Renew(const std::string& topic, bool writers, int expected) {
  int renewed = 0;
  if (writers) {
    for (auto& w : writers_)
      if (w->topic_ == topic && w->matched() < expected) renewed += w->Renew();
    for (auto& w : serialized_writers_) {
      if (w->topic_ != topic) continue;
      int matched = 0;
      {
        std::lock_guard<std::mutex> lock(w->mutex_);
        matched = WriterMatched(w->writer_);
      }
      if (matched < expected) renewed += w->Renew();
    }
  } else {
    for (auto& r : readers_)
      if (r->topic_ == topic && r->Matched() < expected) renewed += r->Renew();
    for (auto& r : serialized_readers_)
      if (r->topic_ == topic && r->Matched() < expected) renewed += r->Renew();
  }
  return renewed;
}

void DdsParticipant::Reap() {
  // Retired generations stay until the participant goes: their readers are kept (kRetireS).
  for (auto& r : readers_) r->Reap(false);
  for (auto& r : serialized_readers_) r->Reap(false);
}

DdsParticipant::DdsParticipant() = default;

DdsParticipant::~DdsParticipant() {
  // No callback after this block: serialized subscriptions closed (their last samples delivered),
  // typed readers' listeners detached. Then endpoints, then the participant.
  for (auto& r : serialized_readers_) r->Close();
  for (auto& r : readers_) {
    std::unique_lock<std::shared_mutex> lock(r->entities_);
    for (fdds::DataReader* d : r->graveyard_) d->set_listener(nullptr);
    for (fdds::DataReader* d : {r->reader_, r->retired_})
      if (d != nullptr) d->set_listener(nullptr);
  }
  serialized_readers_.clear();
  readers_.clear();
  serialized_writers_.clear();
  writers_.clear();
  for (auto& g : retired_gens_) DeleteGeneration(g);
  DeleteGeneration(gen_);
}

Status DdsParticipant::GetTopic(const std::string& topic, const TypeInfo& type, const std::string& given_ros2_name) {
  std::string added;  // the DDS topic, when this call made it
  Status s = AddTopicOnce(topic, type, given_ros2_name, &added);
  // Outside mutex_: the check takes it. Endpoints of the topic discovered before it existed here.
  if (s.ok() && !added.empty()) listener_->CheckDiscovered(added);
  return s;
}

Status DdsParticipant::AddTopicOnce(const std::string& topic, const TypeInfo& type, const std::string& given_ros2_name,
                                    std::string* added) {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::string dds_type = type.dds_name();
  // A name starting with '/' is a ROS 2 topic's own (a watcher's `dyad echo /arm/pose`); graph
  // topics never start with '/' (validation).
  const std::string ros2_name = given_ros2_name.empty() && !topic.empty() && topic[0] == '/' ? topic : given_ros2_name;
  const std::string dds_topic = ros2_name.empty() ? topic : Ros2DdsTopic(ros2_name);
  if (auto it = topic_types_.find(topic); it != topic_types_.end()) {
    if (it->second != dds_type)
      return Status::InvalidArgument("topic '" + topic + "' already carries " + it->second + ", not " + dds_type);
    auto dds = dds_topics_.find(topic);
    if ((dds == dds_topics_.end() ? topic : dds->second) != dds_topic)
      return Status::InvalidArgument("topic '" + topic + "' is already DDS topic '" +
                                     (dds == dds_topics_.end() ? topic : dds->second) + "', not '" + dds_topic + "'");
    return Status::OK();
  }
  if (Status s = AddTopic(gen_, topic, dds_topic, type); !s.ok()) return s;
  topic_types_[topic] = dds_type;
  topic_infos_[topic] = &type;
  if (!ros2_name.empty()) {
    dds_topics_[topic] = dds_topic;
    ros2_topics_[dds_topic] = topic;
  }
  *added = dds_topic;
  return Status::OK();
}

namespace {
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

// A guest's (kWatcher's) reliable volatile writer keeps its last 100 samples, whatever the
// topic's depth. Discovery is not symmetric: the guest's writer may match a graph reader (and the
// guest start writing) a moment before that reader matches the writer; the reader then learns
// the writer's first sequence number from its first heartbeat and asks for what it missed, which
// a depth-1 history has already dropped (`dyad bag play` lost its first sample that way in CI);
// up to 100 written before the match are now repaired. Readers keep their own depth; writers
// with KEEP_LAST never wait for them. Not TRANSIENT_LOCAL writers (the launchers' latched
// dyad/processes state): a late joiner must get their last sample, not their last 100.
constexpr int32_t kGuestWriterDepth = 100;
void KeepForLateMatches(fdds::DataWriterQos& q) {
  if (q.reliability().kind == fdds::RELIABLE_RELIABILITY_QOS && q.durability().kind == fdds::VOLATILE_DURABILITY_QOS &&
      q.history().kind == fdds::KEEP_LAST_HISTORY_QOS)
    q.history().depth = std::max(q.history().depth, kGuestWriterDepth);
}
}  // namespace

StatusOr<TypedReader*> DdsParticipant::CreateReader(const std::string& topic, const TypeInfo& type, const TopicQos& qos,
                                                    std::function<void()> on_data) {
  if (Status st = GetTopic(topic, type, qos.ros2_name); !st.ok()) return st;
  fdds::DataReaderQos rq = fdds::DATAREADER_QOS_DEFAULT;
  ApplyQos(rq, qos);
  std::unique_ptr<DdsReader> r(new DdsReader());
  r->topic_ = topic;
  if (scope_ == Scope::kWatcher) rq.data_sharing().off();
  r->listener_ = std::make_unique<DdsReader::Listener>(std::move(on_data), qos.liveliness_ms > 0);
  fdds::StatusMask mask = fdds::StatusMask::data_available();
  mask << fdds::StatusMask::subscription_matched() << fdds::StatusMask::liveliness_changed()
       << fdds::StatusMask::requested_deadline_missed();
  auto* listener = r->listener_.get();
  r->make_ = [this, topic, rq, listener, mask] {
    // Created without a listener, which is attached once it counts (no callback before).
    fdds::DataReader* d = NewReader(topic, rq);
    if (d == nullptr) return d;
    listener->SetCurrent(d);
    d->set_listener(listener, mask);
    return d;
  };
  r->destroy_ = DeleteReader;
  r->reader_ = r->make_();
  if (r->reader_ == nullptr) return Status::Internal("cannot create reader on topic '" + topic + "'" + SecurityHint("subscribe to"));
  readers_.push_back(std::move(r));
  return readers_.back().get();
}

StatusOr<TypedWriter*> DdsParticipant::CreateWriter(const std::string& topic, const TypeInfo& type, const TopicQos& qos) {
  if (Status st = GetTopic(topic, type, qos.ros2_name); !st.ok()) return st;
  fdds::DataWriterQos wq = fdds::DATAWRITER_QOS_DEFAULT;
  ApplyQos(wq, qos);
  if (scope_ == Scope::kWatcher) KeepForLateMatches(wq);
  std::unique_ptr<DdsWriter> w(new DdsWriter());
  w->topic_ = topic;
  w->make_ = [this, topic, wq] { return NewWriter(topic, wq); };
  w->destroy_ = DeleteWriter;
  w->writer_ = w->make_();
  if (w->writer_ == nullptr) return Status::Internal("cannot create writer on topic '" + topic + "'" + SecurityHint("publish"));
  writers_.push_back(std::move(w));
  return writers_.back().get();
}

StatusOr<SerializedSubscription*> DdsParticipant::CreateSerializedReader(const std::string& topic, const TypeInfo& type,
                                                                        const TopicQos& qos, const Clock* clock,
                                                                        SerializedCallback callback) {
  auto r = MakeSerializedReader(topic, type, qos, clock, std::move(callback), /*on_demand=*/false);
  if (!r.ok()) return r.status();
  return r.value();
}

StatusOr<OnDemandReader*> DdsParticipant::CreateOnDemandReader(const std::string& topic, const TypeInfo& type,
                                                               const TopicQos& qos, const Clock* clock,
                                                               SerializedCallback callback) {
  auto r = MakeSerializedReader(topic, type, qos, clock, std::move(callback), /*on_demand=*/true);
  if (!r.ok()) return r.status();
  return r.value();
}

StatusOr<DdsSerializedReader*> DdsParticipant::MakeSerializedReader(const std::string& topic, const TypeInfo& type,
                                                                    const TopicQos& qos, const Clock* clock,
                                                                    SerializedCallback callback, bool on_demand) {
  if (Status st = GetTopic(topic, type, qos.ros2_name); !st.ok()) return st;
  fdds::DataReaderQos rq = fdds::DATAREADER_QOS_DEFAULT;
  ApplyQos(rq, qos);
  if (qos.keep_all) {
    // KEEP_ALL alone still caps the history (5000 samples, 400 per instance by default): samples
    // that pile up while the callback waits (a full recorder queue) must not be refused.
    rq.resource_limits().max_samples = fdds::LENGTH_UNLIMITED;
    rq.resource_limits().max_samples_per_instance = fdds::LENGTH_UNLIMITED;
    rq.resource_limits().max_instances = fdds::LENGTH_UNLIMITED;
  }
  if (scope_ == Scope::kWatcher) rq.data_sharing().off();
  std::unique_ptr<DdsSerializedReader> r(new DdsSerializedReader());
  r->topic_ = topic;
  r->clock_ = clock;
  r->callback_ = std::move(callback);
  r->scratch_ = std::make_unique<DdsSerializedReader::Scratch>(type);
  r->listener_ = std::make_unique<DdsSerializedReader::Listener>(r.get());
  // The listener is attached once the reader is in place (its callback drains reader_); samples
  // that came in between are drained right after. A renewal's new reader is made the same way.
  r->make_ = [this, topic, rq] { return NewReader(topic, rq); };
  r->destroy_ = DeleteReader;
  if (on_demand) {
    r->started_ = false;  // no DDS reader until Start()
  } else {
    r->reader_ = r->make_();
    if (r->reader_ == nullptr) return Status::Internal("cannot create reader on topic '" + topic + "'" + SecurityHint("subscribe to"));
    r->exists_.store(true, std::memory_order_release);
    r->listener_->SetCurrent(r->reader_);
    r->reader_->set_listener(r->listener_.get(), kSerializedMask);
    std::lock_guard<std::mutex> lock(r->mutex_);
    r->Drain();
  }
  serialized_readers_.push_back(std::move(r));
  return serialized_readers_.back().get();
}

StatusOr<SerializedWriter*> DdsParticipant::CreateSerializedWriter(const std::string& topic,
                                                                                      const TypeInfo& type,
                                                                                      const TopicQos& qos,
                                                                                      const Clock* clock) {
  if (Status st = GetTopic(topic, type, qos.ros2_name); !st.ok()) return st;
  fdds::DataWriterQos wq = fdds::DATAWRITER_QOS_DEFAULT;
  ApplyQos(wq, qos);
  if (scope_ == Scope::kWatcher) KeepForLateMatches(wq);
  std::unique_ptr<DdsSerializedWriter> w(new DdsSerializedWriter());
  w->topic_ = topic;
  w->type_ = &type;
  w->clock_ = clock;
  w->scratch_ = std::make_unique<DdsSerializedWriter::Scratch>(type);
  w->make_ = [this, topic, wq] { return NewWriter(topic, wq); };
  w->destroy_ = DeleteWriter;
  w->writer_ = w->make_();
  if (w->writer_ == nullptr) return Status::Internal("cannot create writer on topic '" + topic + "'" + SecurityHint("publish"));
  serialized_writers_.push_back(std::move(w));
  return serialized_writers_.back().get();
}

int DdsParticipant::MatchedReadersOf(const std::string& topic) const {
  int most = 0;
  for (const auto& w : writers_)
    if (w->topic_ == topic) most = std::max(most, w->matched());
  for (const auto& w : serialized_writers_)
    if (w->topic_ == topic) {
      std::lock_guard<std::mutex> lock(w->mutex_);
      most = std::max(most, WriterMatched(w->writer_));
    }
  return most;
}

int DdsParticipant::MatchedWritersOf(const std::string& topic) const {
  int most = 0;
  for (const auto& r : readers_)
    if (r->topic() == topic) most = std::max(most, r->Matched());
  for (const auto& r : serialized_readers_)
    if (r->topic() == topic && r->exists()) most = std::max(most, r->Matched());
  return most;
}

}  // namespace dyad
