#include "dyad/introspect.hpp"

#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <ostream>
#include <set>
#include <thread>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/rtps/common/SerializedPayload.h>

#include "dds_participant.hpp"

namespace fdds = eprosima::fastdds::dds;

namespace dyad {
namespace {

using Steady = std::chrono::steady_clock;

std::atomic<bool> g_interrupted{false};
extern "C" void OnInterrupt(int) { g_interrupted.store(true); }

// Ctrl-C ends echo/hz cleanly (participant deleted, no shared-memory leftovers).
struct InterruptScope {
  InterruptScope() {
    g_interrupted.store(false);
    struct sigaction sa {};
    sa.sa_handler = OnInterrupt;
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
  }
  ~InterruptScope() {
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
  }
  struct sigaction old_int {}, old_term {};
};

std::unique_ptr<DdsParticipant> Join(const IntrospectOptions& o, std::ostream& err) {
  auto p = DdsParticipant::Create(o.domain_id, "dyad/introspect", nullptr);
  if (!p.ok()) {
    err << p.status().message() << "\n";
    return nullptr;
  }
  return std::move(p.value());
}

// Waits until some writer of `topic` is discovered; returns its DDS type name or "".
std::string DiscoverType(DdsParticipant& p, const std::string& topic, double wait_s) {
  const auto end = Steady::now() + std::chrono::duration<double>(wait_s);
  while (Steady::now() < end && !g_interrupted.load()) {
    for (const auto& e : p.Discovered())
      if (e.writer && e.topic == topic) return e.type;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return "";
}

const TypeInfo* ResolveType(const Catalog& catalog, const std::string& dds_type, const std::string& topic, std::ostream& err) {
  for (const TypeInfo* t : catalog.MessageTypes()) {
    if (t->dds_name() == dds_type) return t;
  }
  const std::string base = dds_type.substr(0, dds_type.find('#'));
  for (const TypeInfo* t : catalog.MessageTypes())
    if (t->name == base) {
      err << "topic '" << topic << "' carries " << dds_type << " but this dyad knows " << t->dds_name()
          << " (same IDL name, different definition): rebuild from the same idl/\n";
      return nullptr;
    }
  err << "topic '" << topic << "' carries " << dds_type << ", a type this dyad does not know\n";
  return nullptr;
}

// A raw reader: takes samples as the type's C++ object and re-serialises them for printing.
class RawReader {
 public:
  RawReader(DdsParticipant& p, const TypeInfo& type, const std::string& topic) : type_(type) {
    support_ = fdds::TypeSupport(type.make_type_support());
    auto* dp = p.raw();
    if (dp->find_type(type.dds_name()).empty()) support_.register_type(dp, type.dds_name());
    topic_ = dp->create_topic(topic, type.dds_name(), fdds::TOPIC_QOS_DEFAULT);
    sub_ = dp->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
    fdds::DataReaderQos q = fdds::DATAREADER_QOS_DEFAULT;
    q.reliability().kind = fdds::BEST_EFFORT_RELIABILITY_QOS;  // matches every writer
    q.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
    q.history().depth = 100;
    if (topic_ && sub_) reader_ = sub_->create_datareader(topic_, q);
    sample_ = support_->createData();
    payload_.reserve(support_->m_typeSize + 1024);
  }
  ~RawReader() {
    if (sample_) support_->deleteData(sample_);
  }
  bool ok() const { return reader_ != nullptr; }
  // Next sample, serialised; false when none is waiting.
  bool Next(std::vector<uint8_t>* bytes) {
    fdds::SampleInfo info;
    while (reader_->take_next_sample(sample_, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      const uint32_t need = support_->getSerializedSizeProvider(sample_)();
      if (payload_.max_size < need) payload_.reserve(need);
      payload_.length = 0;
      payload_.pos = 0;
      if (!support_->serialize(sample_, &payload_)) continue;
      bytes->assign(payload_.data, payload_.data + payload_.length);
      return true;
    }
    return false;
  }
  bool Wait(double seconds) {
    eprosima::fastrtps::Duration_t d(seconds);
    return reader_->wait_for_unread_message(d);
  }

 private:
  const TypeInfo& type_;
  fdds::TypeSupport support_;
  fdds::Topic* topic_ = nullptr;
  fdds::Subscriber* sub_ = nullptr;
  fdds::DataReader* reader_ = nullptr;
  void* sample_ = nullptr;
  eprosima::fastrtps::rtps::SerializedPayload_t payload_;
};

// A participant reading one topic of a running graph, with the type its writers use.
struct TopicTap {
  std::unique_ptr<DdsParticipant> participant;
  const TypeInfo* type = nullptr;
  std::unique_ptr<RawReader> reader;  // declared last: destroyed before the participant
};

// Joins the domain, waits for a writer of `topic`, resolves its type and opens a reader;
// nullopt (after saying why on `err`) when any of that fails.
std::optional<TopicTap> Tap(const IntrospectOptions& o, const Catalog& catalog, const std::string& topic, std::ostream& err) {
  TopicTap tap;
  tap.participant = Join(o, err);
  if (!tap.participant) return std::nullopt;
  const std::string dds_type = DiscoverType(*tap.participant, topic, o.wait_s);
  if (dds_type.empty()) {
    err << "no writer of topic '" << topic << "' found on domain " << o.domain_id << " within " << o.wait_s << " s\n";
    return std::nullopt;
  }
  tap.type = ResolveType(catalog, dds_type, topic, err);
  if (tap.type == nullptr) return std::nullopt;
  tap.reader = std::make_unique<RawReader>(*tap.participant, *tap.type, topic);
  if (!tap.reader->ok()) {
    err << "cannot create a reader on '" << topic << "'\n";
    return std::nullopt;
  }
  return tap;
}

}  // namespace

int ListTopics(const IntrospectOptions& o, std::ostream& out) {
  auto p = Join(o, out);
  if (!p) return 1;
  std::this_thread::sleep_for(std::chrono::duration<double>(o.wait_s));
  struct Row {
    std::set<std::string> types, participants;
    int writers = 0, readers = 0;
  };
  std::map<std::string, Row> rows;
  for (const auto& e : p->Discovered()) {
    if (e.participant == p->name()) continue;
    Row& r = rows[e.topic];
    r.types.insert(e.type);
    r.participants.insert(e.participant);
    (e.writer ? r.writers : r.readers)++;
  }
  for (const auto& [topic, r] : rows) {
    out << topic << "  ";
    for (const auto& t : r.types) out << t << (r.types.size() > 1 ? " " : "");
    out << "  writers=" << r.writers << " readers=" << r.readers << "  [";
    bool first = true;
    for (const auto& pp : r.participants) out << (first ? "" : ", ") << pp, first = false;
    out << "]" << (r.types.size() > 1 ? "  TYPE MISMATCH" : "") << "\n";
  }
  if (rows.empty()) {
    std::cerr << "dyad topics: no endpoint discovered on domain " << o.domain_id << " within " << o.wait_s
              << " s (a longer --wait helps on a loaded machine or network)\n";
    return 1;
  }
  return 0;
}

int EchoTopic(const IntrospectOptions& o, const Catalog& catalog, const std::string& topic, uint64_t count, double duration_s,
              const SamplePrinter& printer, std::ostream& out, std::ostream& err) {
  InterruptScope scope;
  auto tap = Tap(o, catalog, topic, err);
  if (!tap) return 1;
  const TypeInfo* type = tap->type;
  RawReader& reader = *tap->reader;
  const auto end = duration_s > 0 ? Steady::now() + std::chrono::duration<double>(duration_s) : Steady::time_point::max();
  uint64_t n = 0;
  std::vector<uint8_t> bytes;
  while (!g_interrupted.load() && Steady::now() < end && (count == 0 || n < count)) {
    reader.Wait(0.1);
    while (reader.Next(&bytes)) {
      out << printer(*type, bytes.data(), bytes.size()) << "\n" << std::flush;
      if (count != 0 && ++n >= count) break;
    }
  }
  return 0;
}

int TopicHz(const IntrospectOptions& o, const Catalog& catalog, const std::string& topic, double duration_s, std::ostream& out,
            std::ostream& err) {
  InterruptScope scope;
  auto tap = Tap(o, catalog, topic, err);
  if (!tap) return 1;
  RawReader& reader = *tap->reader;
  const auto start = Steady::now();
  const auto end = duration_s > 0 ? start + std::chrono::duration<double>(duration_s) : Steady::time_point::max();
  auto next_report = start + std::chrono::seconds(1);
  std::vector<double> periods;
  Steady::time_point last{};
  uint64_t total = 0;
  std::vector<uint8_t> bytes;
  while (!g_interrupted.load() && Steady::now() < end) {
    reader.Wait(0.05);
    while (reader.Next(&bytes)) {
      const auto now = Steady::now();
      if (last != Steady::time_point{}) periods.push_back(std::chrono::duration<double>(now - last).count());
      last = now;
      ++total;
    }
    if (Steady::now() >= next_report) {
      next_report += std::chrono::seconds(1);
      if (periods.empty()) {
        out << "no new samples\n";
        continue;
      }
      double sum = 0;
      for (double d : periods) sum += d;
      const double mean = sum / static_cast<double>(periods.size());
      out << std::fixed << std::setprecision(3) << "rate " << 1.0 / mean << " Hz  period mean " << mean * 1e3 << " ms  min "
          << *std::min_element(periods.begin(), periods.end()) * 1e3 << " ms  max "
          << *std::max_element(periods.begin(), periods.end()) * 1e3 << " ms  samples " << total << "\n"
          << std::flush;
      out.unsetf(std::ios::fixed);
      periods.clear();
    }
  }
  return total == 0 ? 1 : 0;
}

}  // namespace dyad
