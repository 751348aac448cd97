// LauncherLink (hosts/launcher_link.hpp) between two launchers of one graph, each the launcher
// of one host, on real Fast DDS participants in this process (a test domain of its own,
// dyad/testing/dds_domain.hpp): the link opens its own participant, so no in-memory transport.
// A failure announced by one host's launcher is taken by the other's, once, and not by its own;
// announcements stamped before a link started (an earlier run's), of another graph, of this
// host or of a process that is not required are not taken. Over TCP the links need two
// machines' addresses (one loopback makes both sides dial each other, which Fast DDS 2.9 drops):
// tests/multihost_test.sh failure:tcp covers it.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <dyad/msg/types.hpp>

#include "dds/dds_participant.hpp"
#include "dyad/testing/dds_domain.hpp"
#include "exec/wall_clock.hpp"
#include "graph/run_partition.hpp"
#include "hosts/launcher_link.hpp"

namespace dyad {
namespace {

using SteadyClock = std::chrono::steady_clock;

// lab on host h1, mind on h2, rec (not required) on h2.
Graph Split(const std::string& name = "split") {
  std::vector<Diagnostic> diags;
  Graph g = ParseGraph("graph: " + name +
                           "\nclock: wall\nprocesses: {lab: {host: h1}, mind: {host: h2}, rec: {host: h2, required: false}}\n"
                           "components:\n"
                           "  h: {type: src, rate_hz: 10, process: lab, outputs: {out: human/input}}\n"
                           "  m: {type: delib, rate_hz: 10, process: mind, inputs: {in: human/input}}\n"
                           "  r: {type: sink, trigger: a, process: rec, inputs: {a: human/input}}\n",
                       "split.yaml", {}, &diags);
  for (const auto& d : diags) ADD_FAILURE() << d.message;
  g.domain_id = testing::DomainForThisProcess();
  return g;
}

std::unique_ptr<LauncherLink> Link(const Graph& g, const std::string& host) {
  auto l = LauncherLink::Open(g, host);
  EXPECT_TRUE(l.ok()) << l.status().message();
  return l.ok() ? std::move(l.value()) : nullptr;
}

// Polls TakeRemoteFailure for up to 30 s.
std::optional<std::string> AwaitRemoteFailure(LauncherLink& link) {
  const auto deadline = SteadyClock::now() + std::chrono::seconds(30);
  while (SteadyClock::now() < deadline) {
    if (auto f = link.TakeRemoteFailure()) return f;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return std::nullopt;
}

// Another launcher of the same run, speaking on dyad/launchers with stamps the test chooses.
class Announcer {
 public:
  explicit Announcer(const Graph& g) {
    DdsParticipant::Options o;
    o.scope = DdsParticipant::Scope::kWatcher;  // as the launchers are
    o.network = g.network;
    o.partitions = {RunPartition(g)};
    auto p = DdsParticipant::Create(g.domain_id, "dyad/launcher/test", std::move(o));
    EXPECT_TRUE(p.ok()) << p.status().message();
    if (!p.ok()) return;
    participant_ = std::move(p.value());
    auto w = CreateRuntimeWriter(participant_.get(), runtime_topics::kLaunchers);
    EXPECT_TRUE(w.ok()) << w.status().message();
    if (w.ok()) writer_ = w.value();
  }
  bool ok() const { return writer_ != nullptr; }

  // Writes "failed" and returns once `readers` launchers have it (acknowledged), within 30 s.
  bool Fail(const std::string& graph, const std::string& process, const std::string& host, int64_t stamp_ns, int readers) {
    const auto deadline = SteadyClock::now() + std::chrono::seconds(30);
    while (writer_->matched() < readers && SteadyClock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    msg::ProcessState m;
    m.header().source("dyad/launcher/" + host);
    m.header().sequence_number(++sequence_);
    m.header().stamp_ns(stamp_ns);
    m.graph_name(graph);
    m.process_name(process);
    m.host(host);
    m.state("failed");
    if (!writer_->Write(&m).ok()) return false;
    return writer_->matched() >= readers && writer_->AwaitAcknowledged(30);
  }

 private:
  std::unique_ptr<DdsParticipant> participant_;
  TypedWriter* writer_ = nullptr;
  uint64_t sequence_ = 0;
};

TEST(LauncherLink, AFailureAnnouncedOnOneHostIsTakenOnTheOtherOnceAndNotOnItsOwn) {
  const Graph g = Split();
  std::unique_ptr<LauncherLink> h1 = Link(g, "h1"), h2 = Link(g, "h2");
  ASSERT_TRUE(h1 && h2);
  // Whether every host acknowledged within its 2 s is a matter of discovery's speed: not asserted.
  (void)h2->AnnounceFailure("mind", 1);
  (void)h1->AnnounceFailure("lab", 0);
  // h1's first report is h2's mind, not its own lab (which its own reader also received).
  EXPECT_EQ(AwaitRemoteFailure(*h1), "process 'mind' on host 'h2' failed for good (after 1 restart)");
  EXPECT_EQ(AwaitRemoteFailure(*h2), "process 'lab' on host 'h1' failed for good");
  // Once: nothing more, though both announcements are still arriving or kept.
  EXPECT_EQ(h1->TakeRemoteFailure(), std::nullopt);
  EXPECT_EQ(h2->TakeRemoteFailure(), std::nullopt);
}

TEST(LauncherLink, OnlyAFreshFailureOfThisGraphsRequiredProcessOnAnotherHostIsTaken) {
  const Graph g = Split();
  const int64_t before_start = WallNowNs() - 3'600'000'000'000;  // an hour before: an earlier run's
  std::unique_ptr<LauncherLink> h1 = Link(g, "h1");
  ASSERT_TRUE(h1);
  Announcer other(g);
  ASSERT_TRUE(other.ok());
  // Each is acknowledged by h1's reader (in its history) before the next is written.
  ASSERT_TRUE(other.Fail(g.name, "mind", "h2", before_start, 1));
  ASSERT_TRUE(other.Fail("other_graph", "mind", "h2", WallNowNs(), 1));
  ASSERT_TRUE(other.Fail(g.name, "lab", "h1", WallNowNs(), 1));  // this host's own
  ASSERT_TRUE(other.Fail(g.name, "rec", "h2", WallNowNs(), 1));  // required: false
  EXPECT_EQ(h1->TakeRemoteFailure(), std::nullopt);
  ASSERT_TRUE(other.Fail(g.name, "mind", "h2", WallNowNs(), 1));
  EXPECT_EQ(AwaitRemoteFailure(*h1), "process 'mind' on host 'h2' failed for good");
}

TEST(LauncherLink, RestartNoticeNamesTheProcessAndWhatIsReset) {
  const Graph g = Split();
  EXPECT_EQ(RestartNotice(g, "mind", "h2", 2), "process 'mind' on host 'h2' restarted (restart 2): its components' state is reset (m: delib)");
}

}  // namespace
}  // namespace dyad
