// Typed endpoints (DdsReader, DdsWriter: dds_participant.hpp) and the participant's endpoint
// bookkeeping. A typed reader takes samples as the type's C++ object on the component's thread;
// its listener (Fast DDS's threads) calls on_data and keeps the health counts (matched writers,
// alive writers, deadline misses) as atomics. Creation turns a TopicQos into DDS reader/writer
// QoS (ApplyQos; a watcher's readers without data sharing, its writers with KeepForLateMatches).
// Renewal (see kRetireS): a reader keeps its old DDS reader until Reap lets it go, taking from
// it first and each sample once; a writer switches at once. Matches, Renew, Reap and
// MatchedReadersOf/WritersOf cover every endpoint, serialized ones too (dds_serialized.cpp).
#include "dds/dds_internal.hpp"
#include "dds/network_qos.hpp"

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>

#include <algorithm>
#include <shared_mutex>

namespace dyad {

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

int DdsReader::AliveWriters() const { return listener_->alive_writers(); }
uint64_t DdsReader::DeadlineMisses() const { return listener_->deadline_misses(); }

DdsReader::~DdsReader() {
  if (!destroy_) return;
  for (fdds::DataReader* d : graveyard_) destroy_(d);
  destroy_(retired_.load());
  destroy_(reader_.load());
}

// One taker at a time (the port's component, whose steps never overlap; the runtime's own
// readers under their owner's lock): seen_ needs no lock of its own. The entities are loaded
// without one (see DdsReader): reader_ first, then retired_.
bool DdsReader::TakeNext(void* sample) {
  fdds::DataReader* const current = reader_.load(std::memory_order_acquire);
  fdds::DataReader* const retired = retired_.load(std::memory_order_acquire);
  fdds::SampleInfo& info = *info_;
  for (fdds::DataReader* r : {retired, current}) {  // the retired one's samples are older
    if (r == nullptr) continue;
    while (r->take_next_sample(sample, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data && FreshSample(seen_, info)) return true;
  }
  return false;
}

uint64_t DdsReader::Unread() const {
  fdds::DataReader* const current = reader_.load(std::memory_order_acquire);
  fdds::DataReader* const retired = retired_.load(std::memory_order_acquire);
  return current->get_unread_count() + (retired != nullptr && retired != current ? retired->get_unread_count() : 0);
}

int DdsReader::Matched() const { return listener_->matched(); }

// Under renewal_ throughout (one renewal at a time); make_() waits for the old entity's callbacks
// in flight (CallbackGate), none of which takes renewal_.
bool DdsReader::Renew() {
  MutexLock lock(renewal_);
  if (retired_.load(std::memory_order_relaxed) != nullptr) return false;  // its retired reader may hold samples
  fdds::DataReader* fresh = make_();  // counted by the listener from now on
  if (fresh == nullptr) return false;
  retired_at_ = std::chrono::steady_clock::now();
  retired_.store(reader_.load(std::memory_order_relaxed), std::memory_order_release);
  reader_.store(fresh, std::memory_order_release);  // after retired_: see DdsReader
  return true;
}

bool DdsReader::Reap(bool force) {
  MutexLock lock(renewal_);
  fdds::DataReader* const retired = retired_.load(std::memory_order_relaxed);
  if (retired == nullptr) return true;
  if (!force && !RetiredDone(retired, retired_at_)) return false;
  graveyard_.push_back(retired);  // deleted with this reader (kRetireS); a take may still use it
  retired_.store(nullptr, std::memory_order_release);
  return true;
}

// A reliable writer deleted with samples in flight loses them for remote readers (a recorder in
// another process): give acknowledgments a moment first. Returns at once when all are acked,
// when nothing matched, or for best-effort writers.
void AwaitAcks(fdds::DataWriter* w) {
  if (w != nullptr) w->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(0.5));
}

bool DdsWriter::AwaitAcknowledged(double timeout_s) {
  std::shared_lock<EntityLock> lock(entities_);
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
    std::unique_lock<EntityLock> lock(entities_);
    old = std::exchange(writer_, fresh);
  }
  destroy_(old);
  return true;
}

Status DdsWriter::Write(const void* sample) {
  std::shared_lock<EntityLock> lock(entities_);
  if (!writer_->write(const_cast<void*>(sample)))
    return Status::IOError("topic '" + topic_ + "': DDS write failed");
  return Status::OK();
}

Status DdsWriter::WriteStamped(const void* sample, int64_t stamp_ns) {
  std::shared_lock<EntityLock> lock(entities_);
  if (writer_->write_w_timestamp(const_cast<void*>(sample), fdds::HANDLE_NIL, TimeOfNs(stamp_ns)) != ReturnCode_t::RETCODE_OK)
    return Status::IOError("topic '" + topic_ + "': DDS write failed");
  return Status::OK();
}

int DdsWriter::matched() const {
  std::shared_lock<EntityLock> lock(entities_);
  return WriterMatched(writer_);
}

// An entity goes with the publisher or subscriber (of whichever generation) that made it.
void DeleteReader(fdds::DataReader* d) {
  if (d == nullptr) return;
  d->set_listener(nullptr);
  const_cast<fdds::Subscriber*>(d->get_subscriber())->delete_datareader(d);
}
void DeleteWriter(fdds::DataWriter* d) {
  if (d != nullptr) const_cast<fdds::Publisher*>(d->get_publisher())->delete_datawriter(d);
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

StatusOr<TypedReader*> DdsParticipant::CreateReader(const std::string& topic, const TypeInfo& type, const TopicQos& qos,
                                                    std::function<void()> on_data) {
  if (Status st = GetTopic(topic, type, qos.ros2_name); !st.ok()) return st;
  fdds::DataReaderQos rq = fdds::DATAREADER_QOS_DEFAULT;
  const TopicQos q = WithLeaseLiveliness(qos, secured_ && scope_ != Scope::kProcessOnly, network_);
  ApplyQos(rq, q);
  std::unique_ptr<DdsReader> r(new DdsReader());
  r->topic_ = topic;
  r->info_ = std::make_unique<fdds::SampleInfo>();
  if (scope_ == Scope::kWatcher) rq.data_sharing().off();
  r->listener_ = std::make_unique<DdsReader::Listener>(std::move(on_data), q.liveliness_ms > 0);
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
  r->reader_.store(r->make_());
  if (r->reader_.load() == nullptr)
    return Status::Internal("cannot create reader on topic '" + topic + "'" + SecurityHint("subscribe to"));
  readers_.push_back(std::move(r));
  return readers_.back().get();
}

StatusOr<TypedWriter*> DdsParticipant::CreateWriter(const std::string& topic, const TypeInfo& type, const TopicQos& qos) {
  if (Status st = GetTopic(topic, type, qos.ros2_name); !st.ok()) return st;
  fdds::DataWriterQos wq = fdds::DATAWRITER_QOS_DEFAULT;
  ApplyQos(wq, WithLeaseLiveliness(qos, secured_ && scope_ != Scope::kProcessOnly, network_));
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
