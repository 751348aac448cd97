// DdsParticipant's life (dds_participant.hpp): Create turns Options into the participant's QoS
// (its scope, the graph's network section: network_qos.hpp, DDS Security: security_qos.hpp) and
// makes the first generation (participant, publishers, subscribers, topics); RenewParticipant
// replaces the generation and moves every endpoint onto it, keeping the old one until the
// participant goes (kRetireS); the destructor stops every callback, then deletes the endpoints,
// then the generations. The endpoints live in dds_endpoints.cpp and dds_serialized.cpp, the
// types and topics in dds_types.cpp and dds_ros2.cpp, discovery in dds_discovery.cpp.
#include "dds/dds_internal.hpp"

#include "dds/network_qos.hpp"
#include "dds/security_qos.hpp"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>

#include <shared_mutex>

namespace dyad {

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
  auto names_key = ApplySecurity(options.security, &qos);  // in a secured graph, qos's name is opaque
  if (!names_key.ok()) return names_key.status().WithContext("DDS participant '" + name + "'");
  p->listener_->ReadNamesWith(names_key.value());
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

void DdsParticipant::DeleteGeneration(Generation& g) {
  if (g.participant == nullptr) return;
  g.participant->set_listener(nullptr);
  g.participant->delete_contained_entities();
  fdds::DomainParticipantFactory::get_instance()->delete_participant(g.participant);
  g = Generation{};
}

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

DdsParticipant::DdsParticipant() = default;

DdsParticipant::~DdsParticipant() {
  // No callback after this block: serialized subscriptions closed (their last samples delivered),
  // typed readers' listeners detached. Then endpoints, then the participant.
  for (auto& r : serialized_readers_) r->Close();
  for (auto& r : readers_) {
    MutexLock lock(r->renewal_);
    for (fdds::DataReader* d : r->graveyard_) d->set_listener(nullptr);
    for (fdds::DataReader* d : {r->reader_.load(), r->retired_.load()})
      if (d != nullptr) d->set_listener(nullptr);
  }
  serialized_readers_.clear();
  readers_.clear();
  serialized_writers_.clear();
  writers_.clear();
  for (auto& g : retired_gens_) DeleteGeneration(g);
  DeleteGeneration(gen_);
}

}  // namespace dyad
