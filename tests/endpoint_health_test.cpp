// Healing endpoints that discovery lost: the decisions of EndpointHealth (hosts/) against a
// transport whose matches the test sets, and the renewal itself (DdsParticipant::Renew) on real
// Fast DDS participants, with samples flowing through it.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include <dyad/msg/types.hpp>

#include "dds/dds_participant.hpp"
#include "dyad/testing/dds_domain.hpp"
#include "hosts/endpoint_health.hpp"

namespace dyad {
namespace {

using SteadyClock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// lab: h writes human/input, m reads it; mind: mind reads human/input, writes robot/intention;
// rec: rec reads both.
Graph ThreeProcesses() {
  std::vector<Diagnostic> diags;
  Graph g = ParseGraph(
      "graph: h\nclock: wall\nprocesses: {lab: {}, mind: {}, rec: {}}\ncomponents:\n"
      "  h: {type: src, rate_hz: 10, process: lab, outputs: {out: human/input}}\n"
      "  m: {type: mix, trigger: a, process: lab, inputs: {a: human/input}}\n"
      "  mind: {type: delib, rate_hz: 10, process: mind, inputs: {in: human/input}, outputs: {out: robot/intention}}\n"
      "  rec: {type: sink, trigger: a, process: rec, inputs: {a: human/input, b: robot/intention}}\n",
      "h.yaml", {}, &diags);
  for (const auto& d : diags) ADD_FAILURE() << d.message;
  return g;
}

// Matches as the test says; Renew is recorded and answered with one renewal.
class FakeTransport final : public Transport {
 public:
  std::vector<EndpointMatch> matches;
  struct Renewal {
    std::string topic;
    bool writers;
    int expected;
  };
  std::vector<Renewal> renewals;
  int reaps = 0;

  std::vector<EndpointMatch> Matches() const override { return matches; }
  int Renew(const std::string& topic, bool writers, int expected) override {
    renewals.push_back({topic, writers, expected});
    return 1;
  }
  void Reap() override { ++reaps; }
  int participant_renewals = 0;
  bool network_up = true;
  bool RenewParticipant() override {
    if (!network_up) return false;
    ++participant_renewals;
    return true;
  }
  StatusOr<TypedReader*> CreateReader(const std::string&, const TypeInfo&, const TopicQos&, std::function<void()>) override {
    return Status::Unimplemented("fake");
  }
  StatusOr<TypedWriter*> CreateWriter(const std::string&, const TypeInfo&, const TopicQos&) override {
    return Status::Unimplemented("fake");
  }
  StatusOr<SerializedSubscription*> CreateSerializedReader(const std::string&, const TypeInfo&, const TopicQos&, const Clock*,
                                                           SerializedCallback) override {
    return Status::Unimplemented("fake");
  }
  StatusOr<SerializedWriter*> CreateSerializedWriter(const std::string&, const TypeInfo&, const TopicQos&, const Clock*) override {
    return Status::Unimplemented("fake");
  }
};

SteadyClock::time_point At(double s) { return SteadyClock::time_point() + std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(s)); }

TEST(EndpointHealth, RenewsAReaderStarvedOfARunningWriter) {
  const Graph g = ThreeProcesses();
  EndpointHealth health(g, "rec", 5);
  FakeTransport t;
  // rec's reader of robot/intention sees none of mind's writer; its human/input reader is fine.
  t.matches = {{"robot/intention", false, false, 0}, {"human/input", false, false, 1}};
  const double k = EndpointHealth::kReaderS;
  for (double s : {0.0, 0.5 * k, 0.95 * k}) {
    ASSERT_TRUE(health.Check(&t, {"lab", "mind"}, 0, At(s)).ok());
    EXPECT_TRUE(t.renewals.empty()) << "at " << s << " s";
  }
  ASSERT_TRUE(health.Check(&t, {"lab", "mind"}, 0, At(k)).ok());
  ASSERT_EQ(t.renewals.size(), 1u);
  EXPECT_EQ(t.renewals[0].topic, "robot/intention");
  EXPECT_FALSE(t.renewals[0].writers);
  EXPECT_EQ(t.renewals[0].expected, 1);
  EXPECT_EQ(health.renewals(), 1);
  EXPECT_EQ(t.reaps, 4);  // every check finishes earlier renewals
  // Healed: nothing more, and a later starvation starts its own clock.
  t.matches[0].matched = 1;
  ASSERT_TRUE(health.Check(&t, {"lab", "mind"}, 0, At(k + 1)).ok());
  t.matches[0].matched = 0;
  ASSERT_TRUE(health.Check(&t, {"lab", "mind"}, 0, At(k + 2)).ok());
  EXPECT_EQ(t.renewals.size(), 1u);
}

TEST(EndpointHealth, ExpectsNothingOfAProcessNotHeardRunning) {
  const Graph g = ThreeProcesses();
  EndpointHealth health(g, "rec", 5);
  FakeTransport t;
  t.matches = {{"robot/intention", false, false, 0}, {"human/input", false, false, 0}};
  // mind and lab stopped, crashed or are cut off: their endpoints are not owed.
  for (double s : {0.0, 5.0, 10.0}) ASSERT_TRUE(health.Check(&t, {}, 0, At(s)).ok());
  EXPECT_TRUE(t.renewals.empty());
  // lab alone running: human/input is owed (lab's writer), robot/intention is not.
  ASSERT_TRUE(health.Check(&t, {"lab"}, 0, At(11.0)).ok());
  ASSERT_TRUE(health.Check(&t, {"lab"}, 0, At(11.0 + EndpointHealth::kReaderS)).ok());
  ASSERT_EQ(t.renewals.size(), 1u);
  EXPECT_EQ(t.renewals[0].topic, "human/input");
}

TEST(EndpointHealth, CountsLocalEndpointsAndWaitsLongerForWriters) {
  const Graph g = ThreeProcesses();
  EndpointHealth health(g, "lab", 5);
  FakeTransport t;
  // lab's writer of human/input: owed lab's own m, mind's and rec's readers (3); it has lab's only.
  t.matches = {{"human/input", true, false, 1}, {"human/input", false, false, 1}};
  static_assert(EndpointHealth::kWriterS > EndpointHealth::kReaderS, "readers (lossless) are renewed first");
  for (double s : {0.0, EndpointHealth::kReaderS, 0.95 * EndpointHealth::kWriterS})
    ASSERT_TRUE(health.Check(&t, {"mind", "rec"}, 0, At(s)).ok());
  EXPECT_TRUE(t.renewals.empty());
  ASSERT_TRUE(health.Check(&t, {"mind", "rec"}, 0, At(EndpointHealth::kWriterS)).ok());
  ASSERT_EQ(t.renewals.size(), 1u);
  EXPECT_TRUE(t.renewals[0].writers);
  EXPECT_EQ(t.renewals[0].expected, 3);
}

TEST(EndpointHealth, FailsWhenRenewalsDoNotHeal) {
  const Graph g = ThreeProcesses();
  EndpointHealth health(g, "rec", 5);
  FakeTransport t;
  t.matches = {{"dyad/processes", false, false, 1}};  // hears itself only, while lab and mind run
  double s = 0;
  ASSERT_TRUE(health.Check(&t, {"lab", "mind"}, 0, At(s)).ok());
  for (int i = 0; i < EndpointHealth::kMaxRenewals; ++i) {
    s += EndpointHealth::kReaderS;
    ASSERT_TRUE(health.Check(&t, {"lab", "mind"}, 0, At(s)).ok());
    ASSERT_TRUE(health.Check(&t, {"lab", "mind"}, 0, At(s + 0.5)).ok());
  }
  EXPECT_EQ(t.renewals.size(), static_cast<size_t>(EndpointHealth::kMaxRenewals));
  EXPECT_EQ(t.renewals.back().expected, 3);
  const Status st = health.Check(&t, {"lab", "mind"}, 0, At(s + EndpointHealth::kReaderS));
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("the reader of 'dyad/processes' matched 1 of 3"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("cannot heal"), std::string::npos) << st.message();
}

TEST(EndpointHealth, RenewsTheParticipantWhenNoOtherProcessIsHeardForALease) {
  const Graph g = ThreeProcesses();
  EndpointHealth health(g, "rec", 5);
  FakeTransport t;
  t.matches = {{"robot/intention", false, false, 0}};
  ASSERT_TRUE(health.Check(&t, {}, 4.9, At(0)).ok());  // lost_s 5
  EXPECT_EQ(t.participant_renewals, 0);
  ASSERT_TRUE(health.Check(&t, {}, 5.0, At(1)).ok());
  EXPECT_EQ(t.participant_renewals, 1);
  EXPECT_TRUE(t.renewals.empty()) << "no endpoint renewal: every endpoint is new";
  // Still silent (a long outage): again once per lease, never an error.
  for (double s = 2; s < 11; s += 1) ASSERT_TRUE(health.Check(&t, {}, 5.0 + s, At(s)).ok());
  EXPECT_EQ(t.participant_renewals, 2);  // at 6 s
  EXPECT_EQ(health.participant_renewals(), 2);
}

TEST(EndpointHealth, RenewsTheParticipantOnlyOnceTheNetworkIsUp) {
  const Graph g = ThreeProcesses();
  EndpointHealth health(g, "rec", 4);
  FakeTransport t;
  t.network_up = false;  // the cable is out: a participant made now would announce loopback only
  for (double s = 4; s < 8; s += 1) ASSERT_TRUE(health.Check(&t, {}, s, At(s)).ok());
  EXPECT_EQ(health.participant_renewals(), 0);
  t.network_up = true;  // back: at the next check, not a lease later
  ASSERT_TRUE(health.Check(&t, {}, 8, At(8)).ok());
  EXPECT_EQ(health.participant_renewals(), 1);
}

// transport: tcp: a silent process keeps its participant (a new one could not listen on the
// process's port); its endpoints are still checked.
TEST(EndpointHealth, WithTcpNeverRenewsTheParticipant) {
  Graph g = ThreeProcesses();
  g.network.transport = NetTransport::kTcp;
  EndpointHealth health(g, "rec", 5);
  FakeTransport t;
  t.matches = {{"robot/intention", false, false, 0}};
  for (double s = 0; s < 12; s += 1) ASSERT_TRUE(health.Check(&t, {}, 5.0 + s, At(s)).ok());
  EXPECT_EQ(t.participant_renewals, 0);
  EXPECT_EQ(health.participant_renewals(), 0);
  t.matches = {{"robot/intention", false, false, 0}};  // mind heard running again, its writer missing
  ASSERT_TRUE(health.Check(&t, {"mind"}, 0, At(12)).ok());
  ASSERT_TRUE(health.Check(&t, {"mind"}, 0, At(12 + EndpointHealth::kReaderS)).ok());
  ASSERT_EQ(t.renewals.size(), 1u);
  EXPECT_EQ(t.renewals[0].topic, "robot/intention");
}

// --- the renewal on Fast DDS -----------------------------------------------------------------

std::unique_ptr<DdsParticipant> Participant(const std::string& name) {
  DdsParticipant::Options o;
  o.scope = DdsParticipant::Scope::kProcessOnly;  // both in this process; no one else's
  o.partitions = {"dyad/renew_test"};
  auto p = DdsParticipant::Create(testing::DomainForThisProcess(), name, std::move(o));
  EXPECT_TRUE(p.ok()) << p.status().message();
  return p.ok() ? std::move(p.value()) : nullptr;
}

// Also lets go of retired readers (kRetireS after a renewal), as the health check does.
bool AwaitMatched(DdsParticipant& p, const std::string& topic, bool writer, int n, DdsParticipant* other = nullptr) {
  const auto deadline = SteadyClock::now() + std::chrono::duration<double>(2 * kRetireS + 5);
  while (SteadyClock::now() < deadline) {
    p.Reap();
    if (other != nullptr) other->Reap();
    for (const auto& e : p.Matches())
      if (e.topic == topic && e.writer == writer && e.matched == n) return true;
    std::this_thread::sleep_for(milliseconds(5));
  }
  return false;
}

// Participant a writes Counter 1, 2, 3, ... on "t"; participant b reads them (depth large enough
// that nothing is dropped for want of room).
class EndpointRenewal : public ::testing::Test {
 protected:
  void SetUp() override {
    a_ = Participant("a");
    b_ = Participant("b");
    ASSERT_TRUE(a_ && b_);
    const TopicQos qos{.reliability = Reliability::kReliable, .depth = 10000};
    auto w = a_->CreateWriter("t", TypeInfoOf<msg::Counter>(), qos);
    auto r = b_->CreateReader("t", TypeInfoOf<msg::Counter>(), qos, nullptr);
    ASSERT_TRUE(w.ok() && r.ok());
    writer_ = w.value();
    reader_ = r.value();
    ASSERT_TRUE(AwaitMatched(*a_, "t", true, 1));
    ASSERT_TRUE(AwaitMatched(*b_, "t", false, 1));
  }
  void Write(int64_t value) {
    msg::Counter c;
    c.value(value);
    ASSERT_TRUE(writer_->Write(&c).ok());
  }
  void Take() {
    msg::Counter c;
    while (reader_->TakeNext(&c)) got_.push_back(c.value());
  }
  // Takes until `last` arrived (5 s at most), then checks nothing came twice or out of order.
  void TakeUntil(int64_t last) {
    const auto deadline = SteadyClock::now() + std::chrono::seconds(5);
    while ((got_.empty() || got_.back() != last) && SteadyClock::now() < deadline) {
      Take();
      std::this_thread::sleep_for(milliseconds(1));
    }
    ASSERT_FALSE(got_.empty());
    EXPECT_EQ(got_.back(), last);
    for (size_t i = 1; i < got_.size(); ++i) ASSERT_LT(got_[i - 1], got_[i]) << "repeated or reordered at " << i;
  }
  // got_ starts 1, 2, ..., n: nothing lost up to n.
  void ExpectContiguousTo(size_t n) {
    ASSERT_GE(got_.size(), n);
    for (size_t i = 0; i < n; ++i) ASSERT_EQ(got_[i], static_cast<int64_t>(i + 1)) << "at " << i;
  }

  std::unique_ptr<DdsParticipant> a_, b_;
  TypedWriter* writer_ = nullptr;
  TypedReader* reader_ = nullptr;
  std::vector<int64_t> got_;
};

TEST_F(EndpointRenewal, AReaderRenewedWhileSamplesFlowLosesAndRepeatsNothing) {
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (int64_t i = 1; i <= 1500; ++i) {
      Write(i);
      std::this_thread::sleep_for(milliseconds(1));
    }
    done = true;
  });
  int renewed = 0, refused = 0;
  const auto start = SteadyClock::now();
  while (!done || reader_->Unread() > 0 || got_.size() < 1500) {
    Take();
    const double t = std::chrono::duration<double>(SteadyClock::now() - start).count();
    if (renewed == 0 && t > 0.3) renewed += b_->Renew("t", false, 2);  // matched 1 < 2: renewed
    if (renewed == 1 && refused == 0 && t > 0.8) {
      refused = 1;
      EXPECT_EQ(b_->Renew("t", false, 2), 0) << "one renewal at a time: the retired reader is still taken from";
    }
    b_->Reap();
    if (t > 20) break;
    std::this_thread::sleep_for(milliseconds(1));
  }
  writer.join();
  EXPECT_EQ(renewed, 1);
  EXPECT_EQ(b_->Renew("t", false, 1), 0) << "a reader that matches what is expected is left alone";
  ASSERT_EQ(got_.size(), 1500u);
  ExpectContiguousTo(1500);
  ASSERT_TRUE(AwaitMatched(*b_, "t", false, 1));
}

TEST_F(EndpointRenewal, ARenewedWriterIsMatchedAgainAndNeverRepeatsASample) {
  for (int64_t i = 1; i <= 400; ++i) {
    if (i == 200) {
      ASSERT_EQ(a_->Renew("t", true, 2), 1);
    }
    Write(i);
    Take();
    std::this_thread::sleep_for(milliseconds(1));
  }
  ASSERT_TRUE(AwaitMatched(*a_, "t", true, 1));
  TakeUntil(400);  // the renewed writer's samples arrive
  ExpectContiguousTo(199);
  // Samples written before the new writer matched the reader may be lost (at most those).
  EXPECT_GE(got_.size(), 200u);
}

TEST_F(EndpointRenewal, RenewedParticipantsKeepEveryEndpointWorking) {
  for (int64_t i = 1; i <= 600; ++i) {
    if (i == 200) {
      ASSERT_TRUE(b_->RenewParticipant());  // the reader's side: lossless
    }
    if (i == 400) {
      ASSERT_TRUE(a_->RenewParticipant());  // the writer's side
    }
    Write(i);
    Take();
    a_->Reap();
    b_->Reap();
    std::this_thread::sleep_for(milliseconds(2));
  }
  // The writer's new participant is found again, however long a loaded machine takes (what it
  // wrote before that is lost: the writer is VOLATILE; under load 600 was once written before
  // the match), and then its samples reach the reader: it keeps writing until one does.
  const auto deadline = SteadyClock::now() + std::chrono::seconds(30);
  for (int64_t next = 601; (got_.empty() || got_.back() < 601) && SteadyClock::now() < deadline; ++next) {
    Write(next);
    Take();
    a_->Reap();
    b_->Reap();
    std::this_thread::sleep_for(milliseconds(10));
  }
  ASSERT_FALSE(got_.empty());
  EXPECT_GE(got_.back(), 601) << "the renewed writer's samples never reached the reader";
  for (size_t i = 1; i < got_.size(); ++i) ASSERT_LT(got_[i - 1], got_[i]) << "repeated or reordered at " << i;
  ExpectContiguousTo(399);  // the reader's participant renewal is lossless
  ASSERT_TRUE(AwaitMatched(*b_, "t", false, 1, a_.get()));
}

}  // namespace
}  // namespace dyad
