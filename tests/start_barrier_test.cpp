// StartBarrier (hosts/start_barrier.hpp) over the in-memory transport: the processes of a graph
// start together at an instant each computes alike, a required process never heard ends the
// wait naming it, another graph's announcements are not counted, a running graph is joined at
// once, and Hear() reports who runs and how long the others have been silent. A local graph's
// timeout says the graph is local and how to open it (graph/network_scope.hpp).
//
// The in-memory transport reports no endpoint matches, so every process is "ready" as soon as it
// waits: what is tested here is the exchange of announcements on dyad/processes.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include <dyad/msg/types.hpp>

#include "exec/wall_clock.hpp"
#include "graph/network_scope.hpp"
#include "hosts/start_barrier.hpp"
#include "memory_transport.hpp"

namespace dyad {
namespace {

using SteadyClock = std::chrono::steady_clock;

// lab: h writes human/input; mind: m reads it. `mind_spec`: mind's process entry.
Graph TwoProcesses(const std::string& mind_spec = "{}", const std::string& name = "duo",
                   const std::string& network = "{start_timeout_s: 1.5}") {
  std::vector<Diagnostic> diags;
  Graph g = ParseGraph("graph: " + name +
                           "\nclock: wall\nnetwork: " + network + "\n"
                           "processes: {lab: {}, mind: " +
                           mind_spec +
                           "}\ncomponents:\n"
                           "  h: {type: src, rate_hz: 10, process: lab, outputs: {out: human/input}}\n"
                           "  m: {type: sink, trigger: a, process: mind, inputs: {a: human/input}}\n",
                       "duo.yaml", {}, &diags);
  for (const auto& d : diags) ADD_FAILURE() << d.message;
  return g;
}

bool Never() { return false; }

// An announcement as another process (or another graph's) would make it.
void AnnounceAs(TypedWriter* w, const std::string& graph, const std::string& process, const std::string& state,
                int64_t ready_ns, int64_t start_ns) {
  msg::ProcessState m;
  m.header().source("dyad/" + process);
  m.header().stamp_ns(WallNowNs());
  m.graph_name(graph);
  m.process_name(process);
  m.state(state);
  m.ready_ns(ready_ns);
  m.start_ns(start_ns);
  ASSERT_TRUE(w->Write(&m).ok());
}

TypedWriter* ProcessesWriter(Transport* t) {
  auto w = CreateRuntimeWriter(t, runtime_topics::kProcesses);
  EXPECT_TRUE(w.ok()) << w.status().message();
  return w.ok() ? w.value() : nullptr;
}

TEST(StartBarrier, TwoProcessesOnOneBusStartAtTheSameInstantAndSeeEachOtherRunning) {
  const Graph g = TwoProcesses();
  testing::MemoryTransport bus;
  StartBarrier lab(g, "lab", "h1", 0), mind(g, "mind", "h2", 0);
  ASSERT_TRUE(lab.Open(&bus).ok());
  ASSERT_TRUE(mind.Open(&bus).ok());

  StatusOr<int64_t> mind_start = Status::Internal("not waited");
  std::thread other([&] { mind_start = mind.Wait(Never); });
  const StatusOr<int64_t> lab_start = lab.Wait(Never);
  other.join();
  ASSERT_TRUE(lab_start.ok()) << lab_start.status().message();
  ASSERT_TRUE(mind_start.ok()) << mind_start.status().message();
  EXPECT_EQ(lab_start.value(), mind_start.value());  // computed alike from the same announcements
  EXPECT_GT(lab_start.value(), 0);
  EXPECT_EQ(lab.graph_start_ns(), lab_start.value());
  EXPECT_EQ(mind.graph_start_ns(), mind_start.value());

  lab.Announce("running");
  mind.Announce("running");
  const StartBarrier::Peers lab_hears = lab.Hear(3600), mind_hears = mind.Hear(3600);
  EXPECT_EQ(lab_hears.running, std::set<std::string>{"mind"});  // not itself
  EXPECT_EQ(mind_hears.running, std::set<std::string>{"lab"});
}

// The start is agreed once every process has activated (issue #45 item 4): a process whose
// Activate waits (the web component's wait for the subject's page) holds the common start, which
// comes after it is ready, not before its wait ended.
TEST(StartBarrier, AProcessStillActivatingHoldsTheCommonStart) {
  const Graph g = TwoProcesses("{}", "duo", "{start_timeout_s: 10}");
  testing::MemoryTransport bus;
  StartBarrier lab(g, "lab", "h1", 0), mind(g, "mind", "h2", 0);
  ASSERT_TRUE(lab.Open(&bus).ok());
  ASSERT_TRUE(mind.Open(&bus).ok());
  ASSERT_TRUE(lab.WaitMatched(Never).ok());
  ASSERT_TRUE(mind.WaitMatched(Never).ok());
  StatusOr<int64_t> lab_start = Status::Internal("not waited");
  std::thread other([&] { lab_start = lab.Wait(Never); });      // lab has activated
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // mind activates meanwhile
  const int64_t activated = WallNowNs();
  const StatusOr<int64_t> mind_start = mind.Wait(Never);
  other.join();
  ASSERT_TRUE(lab_start.ok()) << lab_start.status().message();
  ASSERT_TRUE(mind_start.ok()) << mind_start.status().message();
  EXPECT_EQ(lab_start.value(), mind_start.value());
  EXPECT_GE(mind_start.value(), activated + kStartMarginNs);
}

// A process timing out on one that is still activating says so (not "not seen").
TEST(StartBarrier, ATimeoutNamesAProcessStillActivating) {
  const Graph g = TwoProcesses("{}", "duo", "{start_timeout_s: 0.3}");
  testing::MemoryTransport bus;
  StartBarrier lab(g, "lab", "h1", 0), mind(g, "mind", "h2", 0);
  ASSERT_TRUE(lab.Open(&bus).ok());
  ASSERT_TRUE(mind.Open(&bus).ok());
  ASSERT_TRUE(mind.WaitMatched(Never).ok());  // then its Activate never ends
  const StatusOr<int64_t> start = lab.Wait(Never);
  ASSERT_FALSE(start.ok());
  const std::string& m = start.status().message();
  EXPECT_NE(m.find("'mind' (still activating: a component's Activate waits, e.g. the web component's wait_for_subject_s)"),
            std::string::npos)
      << m;
}

TEST(StartBarrier, ARequiredProcessNeverHeardEndsTheWaitNamingIt) {
  const Graph g = TwoProcesses();
  testing::MemoryTransport bus;
  StartBarrier lab(g, "lab", "h1", 0);
  ASSERT_TRUE(lab.Open(&bus).ok());
  const auto begun = SteadyClock::now();
  const StatusOr<int64_t> start = lab.Wait(Never);
  ASSERT_FALSE(start.ok());
  EXPECT_EQ(start.status().code(), Status::Code::kFailedPrecondition);
  const std::string& m = start.status().message();
  EXPECT_NE(m.find("'mind' (not seen)"), std::string::npos) << m;
  EXPECT_NE(m.find("waited 1.5 s (network.start_timeout_s)"), std::string::npos) << m;
  EXPECT_EQ(m.find("'lab' ("), std::string::npos) << "only mind is missing: " << m;
  EXPECT_GE(SteadyClock::now() - begun, std::chrono::milliseconds(1400));  // it did wait (1.5 s)
  // The graph names no host: it is local (loopback only), and a process on another machine is
  // never seen. The message says so and how to open it (issue #40).
  EXPECT_NE(m.find("; " + LocalScopeNote(g.network)), std::string::npos) << m;
  EXPECT_NE(m.find("the graph is local"), std::string::npos) << m;
  EXPECT_NE(m.find("`network.scope: lan`"), std::string::npos) << m;
}

TEST(StartBarrier, AGraphOfScopeLanThatTimesOutSaysNothingOfTheScope) {
  const Graph g = TwoProcesses("{}", "duo", "{scope: lan, start_timeout_s: 0.3}");
  ASSERT_EQ(g.network.scope, NetScope::kLan);
  testing::MemoryTransport bus;
  StartBarrier lab(g, "lab", "h1", 0);
  ASSERT_TRUE(lab.Open(&bus).ok());
  const StatusOr<int64_t> start = lab.Wait(Never);
  ASSERT_FALSE(start.ok());
  EXPECT_NE(start.status().message().find("'mind' (not seen)"), std::string::npos) << start.status().message();
  EXPECT_EQ(start.status().message().find("local"), std::string::npos) << start.status().message();
}

// graph/network_scope.hpp: said only for a local scope; for a process, the fix of the graph; for
// a watcher, that it reaches this machine only and how to watch a graph of scope lan.
TEST(LocalScopeNote, NamesTheFixForALocalScopeAndNothingForLan) {
  NetworkConfig local;
  ASSERT_EQ(local.scope, NetScope::kLocal);  // the default: a graph that names no other machine
  const std::string process = LocalScopeNote(local);
  EXPECT_NE(process.find("the graph is local (network.scope: local"), std::string::npos) << process;
  EXPECT_NE(process.find("a process on another machine is never seen"), std::string::npos) << process;
  EXPECT_NE(process.find("set `network.scope: lan`"), std::string::npos) << process;
  EXPECT_NE(process.find("name the hosts (network.hosts"), std::string::npos) << process;
  const std::string watcher = LocalScopeNote(local, /*watcher=*/true);
  EXPECT_NE(watcher.find("this watcher is local"), std::string::npos) << watcher;
  EXPECT_NE(watcher.find("--graph"), std::string::npos) << watcher;
  NetworkConfig lan;
  lan.scope = NetScope::kLan;
  EXPECT_EQ(LocalScopeNote(lan), "");
  EXPECT_EQ(LocalScopeNote(lan, /*watcher=*/true), "");
}

TEST(StartBarrier, StoppingEndsTheWaitWithoutAStart) {
  const Graph g = TwoProcesses();
  testing::MemoryTransport bus;
  StartBarrier lab(g, "lab", "h1", 0);
  ASSERT_TRUE(lab.Open(&bus).ok());
  const StatusOr<int64_t> start = lab.Wait([] { return true; });
  ASSERT_TRUE(start.ok()) << start.status().message();
  EXPECT_EQ(start.value(), 0);
}

TEST(StartBarrier, AnotherGraphsAnnouncementsAreNotCounted) {
  const Graph g = TwoProcesses();
  testing::MemoryTransport bus;
  StartBarrier lab(g, "lab", "h1", 0);
  ASSERT_TRUE(lab.Open(&bus).ok());
  TypedWriter* other = ProcessesWriter(&bus);
  ASSERT_NE(other, nullptr);
  // A process "mind" of graph "trio" is ready, and running: neither is this graph's mind.
  AnnounceAs(other, "trio", "mind", "waiting", WallNowNs(), 0);
  AnnounceAs(other, "trio", "mind", "running", WallNowNs(), WallNowNs());
  const StatusOr<int64_t> start = lab.Wait(Never);
  ASSERT_FALSE(start.ok());
  EXPECT_NE(start.status().message().find("'mind' (not seen)"), std::string::npos) << start.status().message();
  EXPECT_TRUE(lab.Hear(3600).running.empty());
}

TEST(StartBarrier, AProcessNotRequiredIsNotWaitedFor) {
  const Graph g = TwoProcesses("{required: false}");
  testing::MemoryTransport bus;
  StartBarrier lab(g, "lab", "h1", 0);
  ASSERT_TRUE(lab.Open(&bus).ok());
  const int64_t before = WallNowNs();
  const StatusOr<int64_t> start = lab.Wait(Never);
  ASSERT_TRUE(start.ok()) << start.status().message();
  EXPECT_GE(start.value(), before + kStartMarginNs);  // its own ready time plus the margin
}

TEST(StartBarrier, AProcessThatHearsTheGraphRunningJoinsAtOnce) {
  const Graph g = TwoProcesses();
  testing::MemoryTransport bus;
  StartBarrier lab(g, "lab", "h1", 1);  // restarted
  ASSERT_TRUE(lab.Open(&bus).ok());
  TypedWriter* mind = ProcessesWriter(&bus);
  ASSERT_NE(mind, nullptr);
  const int64_t graph_start = WallNowNs() - 60'000'000'000;  // a minute ago
  AnnounceAs(mind, g.name, "mind", "running", graph_start - kStartMarginNs, graph_start);
  const int64_t before = WallNowNs();
  const StatusOr<int64_t> start = lab.Wait(Never);
  ASSERT_TRUE(start.ok()) << start.status().message();
  EXPECT_GE(start.value(), before);  // now, not the agreed start long past
  EXPECT_EQ(lab.graph_start_ns(), graph_start);
}

TEST(StartBarrier, HearCountsTheSilenceOfARunningRequiredProcess) {
  const Graph g = TwoProcesses();
  testing::MemoryTransport bus;
  StartBarrier lab(g, "lab", "h1", 0);
  ASSERT_TRUE(lab.Open(&bus).ok());
  TypedWriter* mind = ProcessesWriter(&bus);
  ASSERT_NE(mind, nullptr);
  EXPECT_EQ(lab.Hear(3600).silence_s, 0);  // no one heard: no one owes a word

  AnnounceAs(mind, g.name, "mind", "running", WallNowNs(), WallNowNs());
  StartBarrier::Peers p = lab.Hear(3600);
  EXPECT_EQ(p.running, std::set<std::string>{"mind"});
  EXPECT_LT(p.silence_s, 5);  // just heard

  // Silent from now on: the silence grows, and past `fresh_s` mind no longer counts as running.
  const auto deadline = SteadyClock::now() + std::chrono::seconds(30);
  do {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    p = lab.Hear(1.0);
  } while (p.silence_s <= 1.5 && SteadyClock::now() < deadline);
  EXPECT_GT(p.silence_s, 1.5);
  EXPECT_TRUE(p.running.empty());

  AnnounceAs(mind, g.name, "mind", "stopping", 0, 0);  // a word: silence over, and nothing owed
  p = lab.Hear(3600);
  EXPECT_EQ(p.silence_s, 0);
  EXPECT_TRUE(p.running.empty());
}

TEST(StartBarrier, ASilentProcessNotRequiredOwesNothing) {
  const Graph g = TwoProcesses("{required: false}");
  testing::MemoryTransport bus;
  StartBarrier lab(g, "lab", "h1", 0);
  ASSERT_TRUE(lab.Open(&bus).ok());
  TypedWriter* mind = ProcessesWriter(&bus);
  ASSERT_NE(mind, nullptr);
  AnnounceAs(mind, g.name, "mind", "running", WallNowNs(), WallNowNs());
  const StartBarrier::Peers p = lab.Hear(3600);
  EXPECT_EQ(p.running, std::set<std::string>{"mind"});
  EXPECT_EQ(p.silence_s, 0);
}

}  // namespace
}  // namespace dyad
