// Serialized endpoints (DdsSerializedReader, DdsSerializedWriter: dds_participant.hpp): CDR
// bytes in and out for Context::SubscribeSerialized / AdvertiseSerialized and on-demand
// subscriptions, and DecodeSample (dyad/decode_sample.hpp). Fast DDS 2.9 hands out no received
// payload, so a reader takes the type's C++ object and serialises it again, and a writer decodes
// the bytes into the object it writes; each endpoint reuses one scratch sample and payload. A
// reader's callback runs on the delivering thread under its mutex_; renewal as the typed
// reader's (dds_endpoints.cpp, kRetireS), retired readers drained before they go.
#include "dds/dds_internal.hpp"
#include "dds/network_qos.hpp"

#include <dyad/decode_sample.hpp>

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <algorithm>

namespace dyad {

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
  ApplyQos(rq, WithLeaseLiveliness(qos, secured_ && scope_ != Scope::kProcessOnly, network_));
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
  ApplyQos(wq, WithLeaseLiveliness(qos, secured_ && scope_ != Scope::kProcessOnly, network_));
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

}  // namespace dyad
