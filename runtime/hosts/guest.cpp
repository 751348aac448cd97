// A guest's run (dyad/guest.hpp): its components in a graph of their own, with the watched graph's
// topics, on a watcher's participant, without announcements or statistics.
#include "dyad/guest.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <ostream>
#include <thread>

#include "dyad/interrupt.hpp"
#include "dyad/join_list.hpp"
#include "dyad/run.hpp"
#include "dyad/validate.hpp"
#include "exec/wall_clock.hpp"
#include "hosts/process_run.hpp"
#include "hosts/watcher_join.hpp"

namespace dyad {
namespace {

// The guest's part in the watched graph: nothing to announce; its components activate once the
// endpoints it needs are discovered (or its wait is over), and it starts when they are active.
class GuestSession final : public ProcessSession {
 public:
  GuestSession(const DdsParticipant* participant, const GuestOptions& o) : participant_(participant), o_(o) {}
  Status Open(Transport*) override { return Status::OK(); }
  Status AwaitMatched(const std::function<bool()>& stopping) override {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(o_.watch.wait_s);
    std::vector<std::string> missing = Missing();
    while (!missing.empty() && std::chrono::steady_clock::now() < end && !stopping()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      missing = Missing();
    }
    if (stopping()) return Status::OK();
    // Then 50 ms for the rest of that burst (another reader, say). A guest that writes waits
    // 0.5 s: its writer matched the graph's readers, but they match it only when its announcement
    // reaches their process (discovery is not symmetric; no Fast DDS call tells a writer).
    // Samples written before come late, by repair (dds_endpoints.cpp, KeepForLateMatches): a
    // bag played into a loaded graph had its first samples up to 100 ms late.
    if (!missing.empty())
      std::fprintf(stderr, "warning: %s: not discovered within %g s: %s; going on\n", o_.label.c_str(), o_.watch.wait_s,
                   JoinList(missing).c_str());
    else
      std::this_thread::sleep_for(std::chrono::milliseconds(o_.await_readers.empty() ? 50 : 500));
    return Status::OK();
  }
  StatusOr<int64_t> AwaitStart(const std::function<bool()>&) override {
    start_ns_ = WallNowNs();
    return start_ns_;
  }
  int64_t graph_start_ns() const override { return start_ns_; }
  void Started() override {}
  Status Heartbeat() override { return Status::OK(); }
  void Stopping() override {}
  void Close() override {}
  bool shared_start() const override { return false; }

 private:
  // "a writer of T" / "a reader of T" for every awaited endpoint not matched yet with the
  // guest's own (discovered is not enough: a sample written between the two is lost to it).
  // Every endpoint discovered in the guest's partitions counts (at least one per topic).
  std::vector<std::string> Missing() const {
    std::map<std::pair<std::string, bool>, int> discovered;  // (topic, writer) -> endpoints
    for (const auto& e : participant_->Discovered())
      if (e.same_partition && e.participant != participant_->name()) ++discovered[{e.topic, e.writer}];
    std::vector<std::string> missing;
    for (const auto& t : o_.await_writers)
      if (participant_->MatchedWritersOf(t) < std::max(1, discovered[{t, true}])) missing.push_back("a writer of " + t);
    for (const auto& t : o_.await_readers)
      if (participant_->MatchedReadersOf(t) < std::max(1, discovered[{t, false}])) missing.push_back("a reader of " + t);
    return missing;
  }
  const DdsParticipant* participant_;
  const GuestOptions& o_;
  int64_t start_ns_ = 0;
};

// The topics of the guest's graph: the watched graph's, as its file declares them or its ports
// imply them; false after saying why when that graph is not valid.
bool WatchedTopics(const Graph& watched, const Catalog& catalog, std::vector<TopicConfig>* topics, std::ostream& err) {
  std::vector<Diagnostic> diags;
  const ResolvedGraph resolved = ValidateGraph(watched, catalog, &diags);
  for (const auto& d : diags) err << d.ToString() << "\n";
  if (!diags.empty()) return false;
  for (const auto& [name, rt] : resolved.topics) {
    TopicConfig t = rt.config != nullptr ? *rt.config : TopicConfig{};
    t.name = name;
    t.type = rt.type->name;
    topics->push_back(std::move(t));
  }
  return true;
}

// The topics named in `discover`, with their writers' types; best effort, as a watcher reads
// (without the graph file its QoS is not known, and BEST_EFFORT matches every writer).
bool DiscoveredTopics(const GuestOptions& o, DdsParticipant& participant, const Catalog& catalog,
                      std::vector<TopicConfig>* topics, std::ostream& err) {
  InterruptWatcher interrupt;
  for (const auto& name : o.discover) {
    const std::string dds_type = DiscoverType(participant, name, o.watch.wait_s, interrupt);
    if (interrupt.interrupted()) {
      err << o.label << ": interrupted while discovering '" << name << "'\n";
      return false;
    }
    if (dds_type.empty()) {
      err << o.label << ": no writer of topic '" << name << "' found on domain " << o.watch.domain_id << " within " << o.watch.wait_s
          << " s (to name its type, give the graph: --graph)\n";
      return false;
    }
    const TypeInfo* type = ResolveType(catalog, dds_type, name, err);
    if (type == nullptr) return false;
    TopicConfig t;
    t.name = name;
    t.type = type->name;
    t.reliability = Reliability::kBestEffort;
    topics->push_back(std::move(t));
  }
  return true;
}

}  // namespace

int RunGuest(const GuestOptions& o, const Catalog& catalog, std::ostream& /*out*/, std::ostream& err) {
  std::unique_ptr<DdsParticipant> participant =
      JoinAsWatcher(o.watch, "dyad/guest/" + o.label + "/" + std::to_string(getpid()), err);
  if (!participant) return 1;

  // The components under a `components:` key of their own (each line indented).
  std::string text = "clock: wall\ncomponents:\n";
  for (size_t begin = 0; begin < o.components_yaml.size();) {
    const size_t end = std::min(o.components_yaml.find('\n', begin), o.components_yaml.size());
    text += "  " + o.components_yaml.substr(begin, end - begin) + "\n";
    begin = end + 1;
  }
  std::vector<Diagnostic> diags;
  Graph g = ParseGraph(text, o.label, {}, &diags);
  g.name = o.watched != nullptr ? o.watched->name : (o.watch.graph_name.empty() ? "dyad" : o.watch.graph_name);
  g.domain_id = o.watch.domain_id;
  g.network = o.watch.network;
  g.run = o.watch.run_id;
  if (diags.empty()) {
    const bool known = o.watched != nullptr ? WatchedTopics(*o.watched, catalog, &g.topics, err)
                                            : DiscoveredTopics(o, *participant, catalog, &g.topics, err);
    if (!known) return 2;
  }
  ResolvedGraph resolved;
  if (diags.empty()) {
    resolved = ValidateGraph(g, catalog, &diags);
    if (diags.empty()) DryConfigure(g, resolved, catalog, &diags, {});
  }
  for (const auto& d : diags) err << d.ToString() << "\n";
  if (!diags.empty()) return 2;

  Executor::Options eo;
  eo.process = *g.ProcessNames().begin();
  eo.host = "guest";
  eo.duration_s = o.duration_s;
  eo.guest = true;
  DdsParticipant* raw = participant.get();
  auto holder = std::make_shared<std::unique_ptr<DdsParticipant>>(std::move(participant));
  eo.transport = [holder](const std::string&, bool) -> StatusOr<std::unique_ptr<Transport>> {
    if (!*holder) return Status::FailedPrecondition("the guest's participant was taken already");
    return std::unique_ptr<Transport>(std::move(*holder));
  };
  eo.session = [raw, &o] { return std::make_unique<GuestSession>(raw, o); };
  const ProcessRun run = RunProcess(g, resolved, catalog, eo);
  if (!run.result.ok()) {
    err << o.label << ": " << run.result.message() << "\n";
    return ExitCodeOf(run.result);
  }
  if (run.mismatches > 0) {
    err << o.label << ": " << run.mismatches << " type/QoS mismatch(es) with the graph (see above)\n";
    return 1;
  }
  return 0;
}

}  // namespace dyad
