// DdsParticipant — RAII owner of one Fast DDS DomainParticipant and of every topic, writer and
// reader created on it (the Transport of the runtime, see transport.hpp for the ownership and
// delivery contract). Internal to the runtime.
//
// Every type is registered under TypeInfo::dds_name() ("name#hash"). Discovery callbacks compare
// remote endpoints' type names with ours per topic; a remote endpoint on one of our topics with
// another type (same IDL name, other hash: a layout change) is reported through `on_mismatch`
// naming both participants, because Fast DDS would otherwise match them silently (same name)
// or never match them and say nothing (other name).
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <shared_mutex>
#include <string>
#include <thread>
#include <vector>

#include <dyad/component.hpp>
#include <dyad/graph.hpp>
#include <dyad/security.hpp>
#include <dyad/status.hpp>
#include <dyad/thread_annotations.hpp>

#include "dds/transport.hpp"

namespace eprosima::fastdds::dds {
class DomainParticipant;
class DomainParticipantQos;
class DataReaderQos;
class DataWriterQos;
class Publisher;
class Subscriber;
class Topic;
class DataReader;
class DataWriter;
struct SampleInfo;
}  // namespace eprosima::fastdds::dds

namespace dyad {

// The newest sequence number taken from each writer, so that a renewed reader (below) delivers
// a sample once although its retired and its new DDS reader may both hold it.
class SeenWriters {
 public:
  using Guid = std::array<uint8_t, 16>;
  SeenWriters() { seen_.reserve(8); }
  // False for a sample of `writer` numbered at or below the newest taken from it.
  bool Fresh(const Guid& writer, int64_t sequence);

 private:
  std::vector<std::pair<Guid, int64_t>> seen_;
};

// The lock of a renewable writer's entity pointer (DdsWriter below): shared by every use (a
// write, a status query), exclusive only to swap it, after which the old entity is deleted. Like
// glibc's shared mutex it lets a use through while a swap waits; unlike it, a use costs two
// atomic increments and no call (two uses per bench_pingpong round trip: docs/runtime.md). A
// swap raises a flag and takes its turn when no use is under way, else lowers it and waits; a
// use that meets the raised flag waits for that swap alone (a few pointer stores). For
// std::shared_lock and std::unique_lock. (A reader needs none: its retired entities outlive it.)
class EntityLock {
 public:
  void lock_shared() {
    for (;;) {
      users_.fetch_add(1);  // sequentially consistent with the flag (either side sees the other)
      if (!swapping_.load()) return;
      users_.fetch_sub(1);
      while (swapping_.load(std::memory_order_acquire)) std::this_thread::yield();
    }
  }
  void unlock_shared() { users_.fetch_sub(1, std::memory_order_release); }
  void lock() {
    swappers_.lock();
    for (;;) {
      swapping_.store(true);
      if (users_.load() == 0) return;
      swapping_.store(false);
      std::this_thread::yield();
    }
  }
  void unlock() {
    swapping_.store(false, std::memory_order_release);
    swappers_.unlock();
  }

 private:
  std::atomic<int> users_{0};
  std::atomic<bool> swapping_{false};
  std::mutex swappers_;  // one swap at a time
};

// Renewal (DdsParticipant::Renew, the runtime's healing of endpoints that discovery lost): an
// endpoint object keeps its identity for its port while the DDS entity behind it is replaced by
// a new one (a new GUID, which discovery learns afresh). A reader keeps its old entity as
// `retired_` for kRetireS (until every writer has matched the new one: each side learns the
// other on its own) and takes from it first, each sample once (SeenWriters); it is not renewed
// again before Reap() lets the old one go. A writer switches at once.
// A writer's EntityLock guards its entity pointer against the threads that use it; a reader's
// pointers are atomics that every use loads without a lock (DdsReader).
//
// A retired entity is not deleted during the run but kept, unused (its callbacks dropped), until
// the endpoint goes: Fast DDS 2.9 crashes (a best-effort writer's intra-process delivery to a
// deleted reader, seen with dyad/clock) when a reader is deleted while a writer of the same
// process writes to it, and its retired participant stays with them. Renewals are rare (a
// handful per outage); a retired KEEP_ALL reader is still drained, so nothing piles up.
inline constexpr double kRetireS = 5;

// A reader the runtime polls; `on_data` (may be empty) is called from Fast DDS's delivery thread
// whenever samples arrive. Created and destroyed by DdsParticipant only.
class DdsReader final : public TypedReader {
 public:
  ~DdsReader() override;
  bool TakeNext(void* sample) override;
  uint64_t Unread() const override;
  int AliveWriters() const override;
  uint64_t DeadlineMisses() const override;
  const std::string& topic() const { return topic_; }

 private:
  friend class DdsParticipant;
  class Listener;
  DdsReader() = default;
  int Matched() const;
  bool Renew() EXCLUDES(renewal_);
  bool Reap(bool force) EXCLUDES(renewal_);  // true: nothing retired is left
  std::string topic_;
  // The entities, loaded by every use (a take, an unread count) without a lock: no entity is
  // deleted before this reader (a retired one goes to graveyard_), so a use that loaded a pointer
  // just before a swap still holds a live entity. Renew stores retired_ before reader_ (release)
  // and a take loads reader_ before retired_ (acquire): a take that sees the new entity sees the
  // retired one as well and takes from it first (its samples are older). Only Renew and Reap
  // change them, under renewal_, which no use and no Fast DDS callback takes (a delivery holds
  // its DDS reader's lock while our on_data steps a component that takes from this reader). A
  // shared lock around each take cost eight atomic read-modify-writes per bench_pingpong round trip.
  Mutex renewal_;
  std::atomic<eprosima::fastdds::dds::DataReader*> reader_{nullptr};   // owned by the participant's subscriber
  std::atomic<eprosima::fastdds::dds::DataReader*> retired_{nullptr};  // renewed away, still taken from
  std::chrono::steady_clock::time_point retired_at_ GUARDED_BY(renewal_);
  std::vector<eprosima::fastdds::dds::DataReader*> graveyard_ GUARDED_BY(renewal_);  // retired for good, deleted with this
  // TakeNext's alone: a reader has one taker at a time (its port's component, whose steps never
  // overlap, or the runtime object that owns it, each under its own lock where several threads
  // take), so they need no lock of their own. info_ is made once, not at every take.
  SeenWriters seen_;
  std::unique_ptr<eprosima::fastdds::dds::SampleInfo> info_;
  std::unique_ptr<Listener> listener_;
  std::function<eprosima::fastdds::dds::DataReader*()> make_;
  std::function<void(eprosima::fastdds::dds::DataReader*)> destroy_;
};

class DdsWriter final : public TypedWriter {
 public:
  ~DdsWriter() override;
  Status Write(const void* sample) override;
  // Sets the DDS source timestamp to stamp_ns (the header's stamp), so readers see the writer's
  // runtime clock (simulated time under the stepped clock) rather than the wall clock.
  Status WriteStamped(const void* sample, int64_t stamp_ns) override;
  int matched() const override;
  bool AwaitAcknowledged(double timeout_s) override;

 private:
  friend class DdsParticipant;
  DdsWriter() = default;
  bool Renew();
  std::string topic_;
  mutable EntityLock entities_;                           // as DdsReader's: shared to use writer_, exclusive to swap it
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;  // owned by the participant's publisher
  std::function<eprosima::fastdds::dds::DataWriter*()> make_;
  std::function<void(eprosima::fastdds::dds::DataWriter*)> destroy_;
};

// A reader that hands every sample to a callback as CDR bytes (Context::SubscribeSerialized).
// The sample is taken as the type's C++ object and serialised again (Fast DDS 2.9 offers no
// public access to the received payload); the callback runs on the delivering thread under a
// per-reader mutex, so never concurrently with itself.
// On demand (SubscribeSerializedOnDemand): created stopped, with no DDS reader; the first Start()
// creates it; Stop() stops taking (the DDS reader stays, KEEP_LAST, see kRetireS for why it is
// not deleted) and no callback runs until the next Start(). A plain subscription is started at
// creation and never stopped.
class DdsSerializedReader final : public OnDemandReader {
 public:
  ~DdsSerializedReader() override;
  void Close() override;
  const std::string& topic() const override { return topic_; }
  uint64_t delivered() const override { return delivered_.load(std::memory_order_relaxed); }
  Status Start() override;
  void Stop() override;
  bool started() const override;

 private:
  friend class DdsParticipant;
  class Listener;
  DdsSerializedReader();
  void Drain();  // REQUIRES: mutex_ held; nothing when stopped
  void Drain(eprosima::fastdds::dds::DataReader* reader);  // REQUIRES: mutex_ held
  int Matched() const;
  bool exists() const { return exists_.load(std::memory_order_acquire); }  // a DDS reader was made
  bool Renew();
  bool Reap(bool force);  // true: nothing retired is left
  std::string topic_;
  const Clock* clock_ = nullptr;  // owned by the executor
  SerializedCallback callback_;
  // Serializes the DDS reader's life (Start, Stop, Renew); taken before mutex_, never by a callback.
  std::mutex entity_mutex_;
  mutable std::mutex mutex_;  // serializes Drain (and the callback); reader_/retired_/started_ change under it
  bool closed_ = false;
  bool started_ = true;  // false for an on-demand subscription until Start(), and after Stop()
  std::atomic<bool> exists_{false};
  std::atomic<uint64_t> delivered_{0};
  struct Scratch;
  std::unique_ptr<Scratch> scratch_;  // type support, sample, payload: reused for every sample
  std::unique_ptr<Listener> listener_;
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;   // owned by the participant's subscriber
  eprosima::fastdds::dds::DataReader* retired_ = nullptr;  // renewed away, still drained
  std::chrono::steady_clock::time_point retired_at_;
  std::vector<eprosima::fastdds::dds::DataReader*> graveyard_;  // retired for good, drained, deleted with this
  SeenWriters seen_;
  std::function<eprosima::fastdds::dds::DataReader*()> make_;
  std::function<void(eprosima::fastdds::dds::DataReader*)> destroy_;
};

// Publishes CDR bytes (Context::AdvertiseSerialized): decodes them into the type's C++ object
// and writes that, with the given source timestamp.
class DdsSerializedWriter final : public SerializedWriter {
 public:
  ~DdsSerializedWriter() override;
  const std::string& topic() const override { return topic_; }
  const TypeInfo& type() const override { return *type_; }
  Status Write(std::span<const uint8_t> cdr, int64_t source_stamp_ns) override;
  uint64_t written() const override { return written_; }

 private:
  friend class DdsParticipant;
  DdsSerializedWriter();
  bool Renew();
  std::string topic_;
  const TypeInfo* type_ = nullptr;
  const Clock* clock_ = nullptr;
  mutable std::mutex mutex_;
  uint64_t written_ = 0;
  struct Scratch;
  std::unique_ptr<Scratch> scratch_;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;  // owned by the participant's publisher
  std::function<eprosima::fastdds::dds::DataWriter*()> make_;
  std::function<void(eprosima::fastdds::dds::DataWriter*)> destroy_;
};

// An endpoint seen through discovery.
struct DiscoveredEndpoint {
  bool writer = false;
  std::string topic;
  std::string type;         // DDS type name ("name#hash" for dyad types)
  std::string participant;  // its participant's name
  std::string guid;
  bool same_partition = true;  // shares a partition with this participant: DDS may match it with ours
};

class DdsParticipant final : public Transport {
 public:
  using ProblemHandler = std::function<void(const std::string& message)>;

  // kNetwork: a normal participant of the domain. kProcessOnly: discovery ignores participants
  // of other processes (ignoreParticipantFlags = FILTER_DIFFERENT_PROCESS; the transports stay
  // up), so its endpoints match only endpoints in this process: a stepped (deterministic) run
  // that no other process on the domain can disturb, and that disturbs no one.
  //
  // kWatcher: a guest that watches a running graph (`dyad echo/hz/topics`): UDPv4 only, no
  // shared-memory transport and no data sharing. A watcher may die at any moment (SIGKILL,
  // SIGPIPE of `| head`): with shared memory, the graph's writers would keep pushing into the
  // dead watcher's shared-memory port until Fast DDS's port health check gave up (blocking the
  // writing component's step: steps of 0.3 to 2 s measured), and the next watcher reusing that
  // port could not be reached for seconds. Over UDP a dead peer costs a lost datagram.
  enum class Scope { kNetwork, kProcessOnly, kWatcher };

  struct Options {
    Scope scope = Scope::kNetwork;
    // The graph's network section (discovery, transports, lease; see network_qos.hpp), for
    // kNetwork and kWatcher (a watcher keeps to UDP whatever it says, or connects as a TCP
    // client when the transport is tcp); `process` names the graph's process (its TCP listener).
    NetworkConfig network;
    std::string process;
    // The DDS partitions of every endpoint (empty: the default partition). A run's processes use
    // its one partition (RunPartition, graph/runtime_topics.hpp): endpoints of another run of a
    // graph on the same domain do not match them. Watchers may use patterns ("dyad/demo/*").
    std::vector<std::string> partitions;
    // DDS Security (dyad/security.hpp): this participant's identity; none: security off.
    IdentityFiles security;
    // Type mismatches and incompatible QoS (data cannot flow where it should); Fast DDS threads.
    ProblemHandler on_problem;
    // A writer of one of this participant's topics in partitions none of ours matches: another
    // run's, never delivered here. Reported once per writer; Fast DDS threads.
    ProblemHandler on_foreign_writer;
  };
  static StatusOr<std::unique_ptr<DdsParticipant>> Create(int domain_id, const std::string& name, Options options);
  // Stops every callback, deletes every endpoint created here, then the participant.
  ~DdsParticipant() override;
  DdsParticipant(const DdsParticipant&) = delete;
  DdsParticipant& operator=(const DdsParticipant&) = delete;

  // Transport. Endpoints are owned by the participant (see transport.hpp).
  StatusOr<TypedReader*> CreateReader(const std::string& topic, const TypeInfo& type, const TopicQos& qos,
                                      std::function<void()> on_data) override;
  StatusOr<TypedWriter*> CreateWriter(const std::string& topic, const TypeInfo& type, const TopicQos& qos) override;
  StatusOr<SerializedSubscription*> CreateSerializedReader(const std::string& topic, const TypeInfo& type,
                                                           const TopicQos& qos, const Clock* clock,
                                                           SerializedCallback callback) override;
  StatusOr<OnDemandReader*> CreateOnDemandReader(const std::string& topic, const TypeInfo& type, const TopicQos& qos,
                                                 const Clock* clock, SerializedCallback callback) override;
  StatusOr<SerializedWriter*> CreateSerializedWriter(const std::string& topic, const TypeInfo& type, const TopicQos& qos,
                                                     const Clock* clock) override;

  // Endpoints are created and destroyed on the executor's thread only: call it there.
  std::vector<EndpointMatch> Matches() const override;
  // Renews (see kRetireS above) each endpoint of this kind on `topic` matched with fewer than
  // `expected` endpoints; returns how many. Reap() stops using retired readers that are done.
  // Both on the executor's thread, like Matches().
  int Renew(const std::string& topic, bool writers, int expected) override;
  // Replaces the DDS participant itself (a new GUID prefix, which discovery learns as a new
  // participant) and moves every endpoint onto it, readers losslessly as above; the old one is
  // kept, unused, until this participant goes (see kRetireS). False if the new one cannot be made, or
  // not now: while no network interface is up (NetworkUp), it would announce loopback only.
  bool RenewParticipant() override;
  void Reap() override;

  const std::string& name() const { return name_; }
  // Every remote (or local) endpoint discovered so far that is still alive.
  std::vector<DiscoveredEndpoint> Discovered() const;
  // How many peers' names it keeps (read back from a secured graph's wire names): those of the
  // participants discovered and not since removed or dropped, so it stays as small as the domain
  // however many peers come and go.
  size_t KnownPeerNames() const;
  // The most readers one of this participant's writers of `topic` is matched with, and the most
  // writers one of its readers of `topic` is matched with; 0 when it has none there. Discovery
  // comes before matching: a guest waits on these before its first sample (from the thread that
  // creates the endpoints).
  int MatchedReadersOf(const std::string& topic) const;
  int MatchedWritersOf(const std::string& topic) const;

 private:
  class DiscoveryListener;
  // A DDS participant with its publisher, subscriber and topics (one per name). A renewal makes
  // a new one and retires the old until its endpoints are gone.
  // ROS 2 topics' endpoints (TopicQos::ros2_name) go with the second publisher and subscriber,
  // which are in the default partition, where ROS 2 peers are.
  struct Generation {
    eprosima::fastdds::dds::DomainParticipant* participant = nullptr;
    eprosima::fastdds::dds::Publisher* publisher = nullptr;
    eprosima::fastdds::dds::Subscriber* subscriber = nullptr;
    eprosima::fastdds::dds::Publisher* ros2_publisher = nullptr;
    eprosima::fastdds::dds::Subscriber* ros2_subscriber = nullptr;
    std::map<std::string, eprosima::fastdds::dds::Topic*> topics;  // by graph topic name
  };
  DdsParticipant();
  StatusOr<Generation> MakeGeneration();
  // What a refused endpoint's error adds on a secured participant ("" otherwise).
  std::string SecurityHint(const std::string& verb) const;
  static Status AddTopic(Generation& g, const std::string& topic, const std::string& dds_topic, const TypeInfo& type);
  static void DeleteGeneration(Generation& g);
  // On the current generation; `ros2_name`: a ROS 2 topic's (TopicQos::ros2_name).
  Status GetTopic(const std::string& topic, const TypeInfo& type, const std::string& ros2_name);
  // GetTopic's part under mutex_; *added: the DDS topic when this call created it.
  Status AddTopicOnce(const std::string& topic, const TypeInfo& type, const std::string& ros2_name, std::string* added);
  // The graph topic a discovered DDS topic is ("rt/a" -> the graph's name for ROS 2 topic /a).
  // REQUIRES: mutex_ held.
  std::string TopicOfDds(const std::string& dds_topic) const;
  eprosima::fastdds::dds::DataReader* NewReader(const std::string& topic, const eprosima::fastdds::dds::DataReaderQos& qos);
  eprosima::fastdds::dds::DataWriter* NewWriter(const std::string& topic, const eprosima::fastdds::dds::DataWriterQos& qos);
  // A serialized reader, started (plain) or stopped with no DDS reader yet (on demand).
  StatusOr<DdsSerializedReader*> MakeSerializedReader(const std::string& topic, const TypeInfo& type, const TopicQos& qos,
                                                      const Clock* clock, SerializedCallback callback, bool on_demand);

  std::string name_;
  int domain_id_ = 0;
  NetworkConfig network_;
  std::unique_ptr<eprosima::fastdds::dds::DomainParticipantQos> qos_;
  std::unique_ptr<DiscoveryListener> listener_;
  std::mutex mutex_;  // guards the members below (discovery reads the maps from Fast DDS threads)
  Generation gen_;
  std::vector<Generation> retired_gens_;
  std::map<std::string, std::string> topic_types_;     // topic -> dds type name
  std::map<std::string, const TypeInfo*> topic_infos_;  // topic -> its type
  std::map<std::string, std::string> dds_topics_;       // topic -> DDS topic, for ROS 2 topics only
  std::map<std::string, std::string> ros2_topics_;      // DDS topic "rt/..." -> the graph's topic
  Scope scope_ = Scope::kNetwork;
  bool secured_ = false;  // DDS Security on (Options::security)
  std::vector<std::string> partitions_;
  // Every endpoint created here; destroyed (in this order) by the destructor only.
  std::vector<std::unique_ptr<DdsSerializedReader>> serialized_readers_;
  std::vector<std::unique_ptr<DdsReader>> readers_;
  std::vector<std::unique_ptr<DdsSerializedWriter>> serialized_writers_;
  std::vector<std::unique_ptr<DdsWriter>> writers_;
};

}  // namespace dyad
