// `dyad pub` (dyad/guest.hpp): one topic's samples, published by a guest.
#include <unistd.h>

#include <chrono>
#include <map>
#include <ostream>
#include <set>
#include <thread>

#include "dyad/guest.hpp"
#include "dyad/interrupt.hpp"
#include "dyad/join_list.hpp"
#include "dyad/topic_readers.hpp"
#include "dyad/validate.hpp"
#include "exec/wall_clock.hpp"
#include "graph/graph_topics.hpp"
#include "hosts/watcher_join.hpp"

namespace dyad {
namespace {

class WallClock final : public Clock {
 public:
  int64_t now_ns() const override { return WallNowNs(); }
};

// The topic's type (and QoS) from the graph, the name given or its discovered endpoints; null
// after saying why.
const TypeInfo* TopicType(const PublishOptions& o, const Catalog& catalog, DdsParticipant& participant, TopicQos* qos,
                          ResolvedGraph* resolved_out, const InterruptWatcher& interrupt, std::ostream& err) {
  if (o.watched != nullptr) {
    std::vector<Diagnostic> diags;
    const ResolvedGraph& resolved = *resolved_out = ValidateGraph(*o.watched, catalog, &diags);
    for (const auto& d : diags) err << d.ToString() << "\n";
    if (!diags.empty()) return nullptr;
    auto it = resolved.topics.find(o.topic);
    if (it == resolved.topics.end()) {
      std::vector<std::string> names;
      for (const auto& [name, t] : resolved.topics) names.push_back(name);
      err << "dyad pub: graph '" << o.watched->name << "' has no topic '" << o.topic << "' (its topics: " << JoinList(names) << ")\n";
      return nullptr;
    }
    *qos = QosOf(it->second);
    return it->second.type;
  }
  if (!o.type_name.empty()) {
    const TypeInfo* type = catalog.FindMessageType(o.type_name);
    if (type == nullptr) err << "dyad pub: --type " << o.type_name << ": no message type of that name (dyad types --messages lists them)\n";
    return type;
  }
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.watch.wait_s);
  while (std::chrono::steady_clock::now() < end && !interrupt.interrupted()) {
    for (const auto& e : participant.Discovered())
      if (e.topic == o.topic) return ResolveType(catalog, e.type, o.topic, err);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (!interrupt.interrupted())
    err << "dyad pub: no endpoint of topic '" << o.topic << "' found on domain " << o.watch.domain_id << " within " << o.watch.wait_s
        << " s to take its type from: give --graph or --type\n";
  return nullptr;
}

// The readers the first sample waits for: with the graph, every reader it declares for the topic
// (dyad/topic_readers.hpp: input ports and recorders), as {".../<graph>/<process>": how many in
// that process}; without, anyone's ({"": 1}: any reader). `settle`: more readers may come than
// the graph can say (none declared: a ROS 2 topic the robot's side reads; a web page that
// subscribes through the web component's bridge).
struct ExpectedReaders {
  std::map<std::string, int> per_process;
  bool settle = true;
};

ExpectedReaders ReadersToAwait(const PublishOptions& o, const ResolvedGraph& resolved) {
  ExpectedReaders x;
  if (o.watched != nullptr) {
    x.settle = false;
    for (const DeclaredReader& r : DeclaredReaders(*o.watched, resolved, o.topic)) {
      if (r.kind == DeclaredReader::kWeb) x.settle = true;
      else ++x.per_process["/" + o.watched->name + "/" + o.watched->ProcessOf(*r.component)];
    }
  }
  if (x.per_process.empty()) x = {{{"", 1}}, true};
  return x;
}

// Waits up to wait_s for those readers of the topic, then until this participant's writer has
// matched every reader of the topic discovered in its partitions (discovered is not enough: a
// sample written before the match is lost to a volatile reader).
void AwaitReaders(const PublishOptions& o, const ResolvedGraph& resolved, DdsParticipant& participant,
                  const InterruptWatcher& interrupt, std::ostream& err) {
  const ExpectedReaders expected = ReadersToAwait(o, resolved);
  std::set<std::string> missing;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(o.watch.wait_s);
  auto readers = [&] {
    int n = 0;
    std::map<std::string, int> found;
    for (const auto& e : participant.Discovered())
      if (!e.writer && e.topic == o.topic && e.same_partition && e.participant != participant.name()) {
        ++n;
        for (const auto& [suffix, count] : expected.per_process)
          if (e.participant.ends_with(suffix)) ++found[suffix];
      }
    missing.clear();
    for (const auto& [suffix, count] : expected.per_process)
      if (found[suffix] < count) missing.insert(suffix);
    return n;
  };
  int discovered = readers();
  while ((!missing.empty() || participant.MatchedReadersOf(o.topic) < discovered) && std::chrono::steady_clock::now() < end &&
         !interrupt.interrupted()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    discovered = readers();
  }
  // When the graph cannot say every reader (see ExpectedReaders), nothing says how many there
  // are: the rest of the discovery burst that brought the first (0.5 s), and they are matched
  // too. The wait also lets a reader of another vendor match this writer from its side (seen
  // with Cyclone DDS: a volatile reader ignores samples of a writer it has not matched yet, and a
  // reliable writer's match says nothing about the reader's).
  if (expected.settle && missing.empty()) {
    const auto settle = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
    while (std::chrono::steady_clock::now() < settle && std::chrono::steady_clock::now() < end && !interrupt.interrupted())
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    discovered = readers();
    while (participant.MatchedReadersOf(o.topic) < discovered && std::chrono::steady_clock::now() < end && !interrupt.interrupted())
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (interrupt.interrupted()) return;
  if (!missing.empty())
    err << "warning: dyad pub: no reader of '" << o.topic << "'" << (missing.count("") ? "" : " in the graph's processes (" + JoinList(missing) + ")")
        << " discovered within " << o.watch.wait_s << " s; publishing anyway\n";
  else if (participant.MatchedReadersOf(o.topic) < discovered)
    err << "warning: dyad pub: " << participant.MatchedReadersOf(o.topic) << " of the " << discovered << " readers of '" << o.topic
        << "' matched within " << o.watch.wait_s << " s; publishing anyway\n";
}

}  // namespace

int PublishTopic(const PublishOptions& o, const Catalog& catalog, const SampleMaker& make_sample, std::ostream& out,
                 std::ostream& err) {
  InterruptWatcher interrupt;
  std::unique_ptr<DdsParticipant> participant = JoinAsWatcher(o.watch, "dyad/guest/pub/" + std::to_string(getpid()), err);
  if (!participant) return 1;
  TopicQos qos;
  ResolvedGraph resolved;
  const TypeInfo* type = TopicType(o, catalog, *participant, &qos, &resolved, interrupt, err);
  if (interrupt.interrupted()) return ExitCodeForSignal(interrupt.signal());
  if (type == nullptr) return 2;
  StatusOr<std::vector<uint8_t>> sample = make_sample(*type, 0);
  if (!sample.ok()) {
    err << "dyad pub: " << sample.status().message() << "\n";
    return 2;
  }
  WallClock clock;
  auto writer = participant->CreateSerializedWriter(o.topic, *type, qos, &clock);
  if (!writer.ok()) {
    err << "dyad pub: " << writer.status().message() << "\n";
    return 1;
  }
  AwaitReaders(o, resolved, *participant, interrupt, err);
  const auto period = std::chrono::duration<double>(o.rate_hz > 0 ? 1.0 / o.rate_hz : 0.0);
  const auto start = std::chrono::steady_clock::now();
  uint64_t written = 0;
  for (; (o.count == 0 || written < o.count) && !interrupt.interrupted(); ++written) {
    if (written > 0) {
      sample = make_sample(*type, written);
      if (!sample.ok()) {
        err << "dyad pub: sample " << written << ": " << sample.status().message() << "\n";
        return 2;
      }
      std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(period * written));
      if (interrupt.interrupted()) break;
    }
    if (Status s = (*writer)->Write(*sample, -1); !s.ok()) {
      err << "dyad pub: " << s.message() << "\n";
      return 1;
    }
  }
  out << "dyad pub: " << written << " sample" << (written == 1 ? "" : "s") << " of " << type->name << " on " << o.topic << "\n";
  participant.reset();  // its writer waits for the readers' acknowledgements first (0.5 s at most)
  if (interrupt.interrupted() && o.count != 0) return ExitCodeForSignal(interrupt.signal());
  return 0;
}

}  // namespace dyad
