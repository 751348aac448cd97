// ClockSync (hosts/clock_sync.hpp) between two processes on one in-memory bus, one clock: each
// measures the other's offset (near zero: within half the round trip, as NTP's arithmetic
// promises), publishes it on dyad/clock_offsets, warns once per peer beyond the bound, and stops
// reporting a peer that no longer answers. Another graph's probes are not answered.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <dyad/msg/types.hpp>

#include "hosts/clock_sync.hpp"
#include "memory_transport.hpp"

namespace dyad {
namespace {

using SteadyClock = std::chrono::steady_clock;
// A peer is dropped after kWindow unanswered periods (2 s here): a loaded machine's pauses are shorter.
constexpr double kPeriodS = 0.25;

Graph TwoProcesses(const std::string& name = "duo") {
  std::vector<Diagnostic> diags;
  Graph g = ParseGraph("graph: " + name +
                           "\nclock: wall\nprocesses: {lab: {}, mind: {}}\ncomponents:\n"
                           "  h: {type: src, rate_hz: 10, process: lab, outputs: {out: human/input}}\n"
                           "  m: {type: sink, trigger: a, process: mind, inputs: {a: human/input}}\n",
                       "duo.yaml", {}, &diags);
  for (const auto& d : diags) ADD_FAILURE() << d.message;
  return g;
}

// Polls `done` every 10 ms for up to 30 s.
template <typename F>
bool Eventually(F done) {
  const auto deadline = SteadyClock::now() + std::chrono::seconds(30);
  while (SteadyClock::now() < deadline) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return done();
}

bool Measures(const ClockSync& s, const std::string& peer) {
  for (const auto& o : s.Offsets())
    if (o.peer_process() == peer) return true;
  return false;
}

// Warnings arrive on the clock-sync thread.
struct Warnings {
  std::mutex mutex;
  std::vector<std::string> lines;
  std::function<void(const std::string&)> Sink() {
    return [this](const std::string& w) {
      std::lock_guard<std::mutex> lock(mutex);
      lines.push_back(w);
    };
  }
  std::vector<std::string> Lines() {
    std::lock_guard<std::mutex> lock(mutex);
    return lines;
  }
};

TEST(ClockSync, TwoProcessesOnOneClockMeasureANearZeroOffset) {
  const Graph g = TwoProcesses();
  testing::MemoryTransport bus;  // outlives both (declared first)
  ClockSync lab(g, "lab", "h1", nullptr), mind(g, "mind", "h2", nullptr);
  ASSERT_TRUE(lab.Open(&bus).ok());
  ASSERT_TRUE(mind.Open(&bus).ok());
  lab.Start(kPeriodS);
  mind.Start(kPeriodS);
  std::vector<msg::ClockOffset> of_lab, of_mind;
  ASSERT_TRUE(Eventually([&] {
    of_lab = lab.Offsets();
    of_mind = mind.Offsets();
    return !of_lab.empty() && !of_mind.empty();
  }));
  for (const ClockSync* s : {&lab, &mind}) {
    const std::vector<msg::ClockOffset>& offsets = s == &lab ? of_lab : of_mind;
    ASSERT_EQ(offsets.size(), 1u);  // one per peer, not itself
    const msg::ClockOffset& o = offsets[0];
    EXPECT_EQ(o.graph_name(), "duo");
    EXPECT_EQ(o.peer_process(), s == &lab ? "mind" : "lab");
    EXPECT_EQ(o.host(), s == &lab ? "h1" : "h2");
    EXPECT_GE(o.round_trip_ns(), 0);
    // One clock: the offset is only the round trip's asymmetry, at most half of it.
    EXPECT_LE(std::llabs(o.offset_ns()), o.round_trip_ns() / 2 + 1) << o.offset_ns() << " ns, round trip " << o.round_trip_ns();
    EXPECT_LT(std::llabs(o.offset_ns()), 1'000'000'000);
  }
  lab.Stop();
  mind.Stop();
}

TEST(ClockSync, OffsetsArePublishedOnTheOffsetsTopic) {
  const Graph g = TwoProcesses();
  testing::MemoryTransport bus;
  auto offsets_reader = CreateRuntimeReader(&bus, runtime_topics::kClockOffsets);
  ASSERT_TRUE(offsets_reader.ok());
  ClockSync lab(g, "lab", "h1", nullptr), mind(g, "mind", "h2", nullptr);
  ASSERT_TRUE(lab.Open(&bus).ok());
  ASSERT_TRUE(mind.Open(&bus).ok());
  lab.Start(kPeriodS);
  mind.Start(kPeriodS);
  bool lab_about_mind = false;
  EXPECT_TRUE(Eventually([&] {
    msg::ClockOffset o;
    while (offsets_reader.value()->TakeNext(&o))
      lab_about_mind |= o.process_name() == "lab" && o.peer_process() == "mind" && o.header().source() == "dyad/lab";
    return lab_about_mind;
  }));
  lab.Stop();
  mind.Stop();
}

TEST(ClockSync, APeerThatStopsAnsweringIsNoLongerReported) {
  const Graph g = TwoProcesses();
  testing::MemoryTransport bus;
  ClockSync lab(g, "lab", "h1", nullptr), mind(g, "mind", "h2", nullptr);
  ASSERT_TRUE(lab.Open(&bus).ok());
  ASSERT_TRUE(mind.Open(&bus).ok());
  lab.Start(kPeriodS);
  mind.Start(kPeriodS);
  ASSERT_TRUE(Eventually([&] { return Measures(lab, "mind"); }));
  mind.Stop();  // its thread answers no more (its reader still takes the requests)
  EXPECT_TRUE(Eventually([&] { return !Measures(lab, "mind"); }));  // after kWindow unanswered requests
  lab.Stop();
}

TEST(ClockSync, AnotherGraphsProcessIsNotMeasured) {
  const Graph duo = TwoProcesses("duo"), trio = TwoProcesses("trio");
  testing::MemoryTransport bus;
  ClockSync lab(duo, "lab", "h1", nullptr), stranger(trio, "mind", "h2", nullptr), mind(duo, "mind", "h2", nullptr);
  ASSERT_TRUE(lab.Open(&bus).ok());
  ASSERT_TRUE(stranger.Open(&bus).ok());
  lab.Start(kPeriodS);
  stranger.Start(kPeriodS);
  // Many periods with only the stranger on the bus: nothing measured.
  std::this_thread::sleep_for(std::chrono::milliseconds(8 * static_cast<int>(kPeriodS * 1000)));
  EXPECT_TRUE(lab.Offsets().empty());
  EXPECT_TRUE(stranger.Offsets().empty());
  // This graph's mind is (the bus works).
  ASSERT_TRUE(mind.Open(&bus).ok());
  mind.Start(kPeriodS);
  EXPECT_TRUE(Eventually([&] { return Measures(lab, "mind"); }));
  EXPECT_TRUE(stranger.Offsets().empty());
  lab.Stop();
  stranger.Stop();
  mind.Stop();
}

TEST(ClockSync, AnOffsetBeyondTheBoundIsSaidOncePerPeer) {
  Graph g = TwoProcesses();
  g.network.max_clock_offset_ms = -1;  // every offset is beyond it (a real skew needs two clocks)
  testing::MemoryTransport bus;
  Warnings warnings;
  ClockSync lab(g, "lab", "h1", warnings.Sink()), mind(g, "mind", "h2", nullptr);
  ASSERT_TRUE(lab.Open(&bus).ok());
  ASSERT_TRUE(mind.Open(&bus).ok());
  lab.Start(kPeriodS);
  mind.Start(kPeriodS);
  ASSERT_TRUE(Eventually([&] { return !warnings.Lines().empty(); }));
  std::this_thread::sleep_for(std::chrono::milliseconds(8 * static_cast<int>(kPeriodS * 1000)));  // many more periods
  lab.Stop();
  mind.Stop();
  const std::vector<std::string> lines = warnings.Lines();
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("process 'mind'"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("network.max_clock_offset_ms"), std::string::npos) << lines[0];
}

}  // namespace
}  // namespace dyad
