// Incompatible QoS: the terms Fast DDS matches a writer and a reader by (dds/qos_match.hpp), and
// whose incompatibility a participant reports: one of its own run's partition, never another
// run's on the same domain (Fast DDS checks QoS before partitions and reports both alike).
#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include <fastdds/dds/core/policy/QosPolicies.hpp>

#include "dds/dds_participant.hpp"
#include "dds/qos_match.hpp"
#include "dyad/msg/types.hpp"
#include "dyad/testing/dds_domain.hpp"

namespace dyad {
namespace {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::Duration_t;

// Each term of Fast DDS 2.9's EDP::valid_matching, alone and together.
TEST(QosMatch, EachTermIsCheckedAsFastDdsChecksIt) {
  const MatchTerms reliable{.reliability = fdds::RELIABLE_RELIABILITY_QOS};
  EXPECT_TRUE(IncompatiblePolicies(reliable, reliable).empty());
  EXPECT_TRUE(IncompatiblePolicies(reliable, MatchTerms{}).empty()) << "a reliable writer serves a best-effort reader";
  EXPECT_EQ(IncompatiblePolicies(MatchTerms{}, reliable), std::vector<fdds::QosPolicyId_t>{fdds::RELIABILITY_QOS_POLICY_ID});

  MatchTerms transient;
  transient.durability = fdds::TRANSIENT_LOCAL_DURABILITY_QOS;
  EXPECT_TRUE(IncompatiblePolicies(transient, MatchTerms{}).empty());
  EXPECT_EQ(IncompatiblePolicies(MatchTerms{}, transient), std::vector<fdds::QosPolicyId_t>{fdds::DURABILITY_QOS_POLICY_ID});

  MatchTerms exclusive;
  exclusive.ownership = fdds::EXCLUSIVE_OWNERSHIP_QOS;
  EXPECT_EQ(IncompatiblePolicies(exclusive, MatchTerms{}), std::vector<fdds::QosPolicyId_t>{fdds::OWNERSHIP_QOS_POLICY_ID});
  EXPECT_EQ(IncompatiblePolicies(MatchTerms{}, exclusive), std::vector<fdds::QosPolicyId_t>{fdds::OWNERSHIP_QOS_POLICY_ID});

  MatchTerms fast, slow;  // deadlines: a writer must promise at least as often as the reader asks
  fast.deadline = Duration_t(0, 100'000'000);
  slow.deadline = Duration_t(1, 0);
  EXPECT_TRUE(IncompatiblePolicies(fast, slow).empty());
  EXPECT_EQ(IncompatiblePolicies(slow, fast), std::vector<fdds::QosPolicyId_t>{fdds::DEADLINE_QOS_POLICY_ID});
  EXPECT_EQ(IncompatiblePolicies(MatchTerms{}, fast), std::vector<fdds::QosPolicyId_t>{fdds::DEADLINE_QOS_POLICY_ID})
      << "no deadline is an infinite one";

  MatchTerms short_lease, manual;  // a writer's lease no longer than asked, its kind no weaker
  short_lease.lease = Duration_t(0, 300'000'000);
  manual.liveliness = fdds::MANUAL_BY_TOPIC_LIVELINESS_QOS;
  EXPECT_TRUE(IncompatiblePolicies(short_lease, MatchTerms{}).empty());
  EXPECT_EQ(IncompatiblePolicies(MatchTerms{}, short_lease), std::vector<fdds::QosPolicyId_t>{fdds::LIVELINESS_QOS_POLICY_ID});
  EXPECT_TRUE(IncompatiblePolicies(manual, MatchTerms{}).empty());
  EXPECT_EQ(IncompatiblePolicies(MatchTerms{}, manual), std::vector<fdds::QosPolicyId_t>{fdds::LIVELINESS_QOS_POLICY_ID});

  MatchTerms no_acks;
  no_acks.disable_positive_acks = true;
  EXPECT_TRUE(IncompatiblePolicies(no_acks, MatchTerms{}).empty());
  EXPECT_EQ(IncompatiblePolicies(MatchTerms{}, no_acks),
            std::vector<fdds::QosPolicyId_t>{fdds::DISABLEPOSITIVEACKS_QOS_POLICY_ID});

  MatchTerms asks_all = reliable;
  asks_all.durability = fdds::TRANSIENT_LOCAL_DURABILITY_QOS;
  asks_all.lease = short_lease.lease;
  EXPECT_EQ(IncompatiblePolicies(MatchTerms{}, asks_all),
            (std::vector<fdds::QosPolicyId_t>{fdds::RELIABILITY_QOS_POLICY_ID, fdds::DURABILITY_QOS_POLICY_ID,
                                              fdds::LIVELINESS_QOS_POLICY_ID}));
  EXPECT_EQ(QosPolicyName(fdds::LIVELINESS_QOS_POLICY_ID), "liveliness");
  EXPECT_EQ(QosPolicyName(fdds::PARTITION_QOS_POLICY_ID), "policy " + std::to_string(fdds::PARTITION_QOS_POLICY_ID));
}

// What a participant said through on_problem and on_foreign_writer (Fast DDS threads).
struct Said {
  std::mutex mutex;
  std::vector<std::string> problems, foreign;
  std::vector<std::string> Problems() {
    std::lock_guard<std::mutex> lock(mutex);
    return problems;
  }
  size_t Foreign() {
    std::lock_guard<std::mutex> lock(mutex);
    return foreign.size();
  }
};

std::unique_ptr<DdsParticipant> Participant(const std::string& name, const std::string& run, Said* said = nullptr) {
  DdsParticipant::Options o;
  o.scope = DdsParticipant::Scope::kProcessOnly;  // its peers are in this process; no one else's
  o.partitions = {"dyad/qos_test/" + run};
  if (said != nullptr) {
    o.on_problem = [said](const std::string& m) {
      std::lock_guard<std::mutex> lock(said->mutex);
      said->problems.push_back(m);
    };
    o.on_foreign_writer = [said](const std::string& m) {
      std::lock_guard<std::mutex> lock(said->mutex);
      said->foreign.push_back(m);
    };
  }
  auto p = DdsParticipant::Create(testing::DomainForThisProcess(), name, std::move(o));
  EXPECT_TRUE(p.ok()) << p.status().message();
  return p.ok() ? std::move(p.value()) : nullptr;
}

template <typename Pred>
bool Await(Pred done, double seconds = 10) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!done() && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  return done();
}

// The run's participant reads "t" with a 300 ms liveliness lease and writes "u" without one.
// Another run's participant on the same domain writes "t" with no lease (infinite: incompatible)
// and reads "u" asking for one (incompatible): Fast DDS calls back both, and the run says
// nothing of it but the foreign writer it ignores. A writer of its own run with the same QoS is
// reported, by name and policies, once.
TEST(IncompatibleQos, AnotherRunsEndpointIsNotReportedAndOneOfThisRunsIs) {
  Said said;
  auto run = Participant("dyad/qos_test/run", "mine", &said);
  ASSERT_TRUE(run);
  const TopicQos leased{.reliability = Reliability::kReliable, .liveliness_ms = 300};
  const TopicQos plain{.reliability = Reliability::kReliable};
  ASSERT_TRUE(run->CreateReader("t", TypeInfoOf<msg::Counter>(), leased, nullptr).ok());
  ASSERT_TRUE(run->CreateWriter("u", TypeInfoOf<msg::Counter>(), plain).ok());

  auto other = Participant("dyad/qos_test/other", "theirs");
  ASSERT_TRUE(other);
  ASSERT_TRUE(other->CreateWriter("t", TypeInfoOf<msg::Counter>(), plain).ok());
  ASSERT_TRUE(other->CreateReader("u", TypeInfoOf<msg::Counter>(), leased, nullptr).ok());
  ASSERT_TRUE(Await([&] { return said.Foreign() == 1; })) << "the other run's writer of 't' is never seen";
  // Fast DDS pairs a discovered endpoint right after reporting it, on the same thread: the
  // callbacks are due by now; give the reader of "u" as long again.
  std::this_thread::sleep_for(std::chrono::seconds(1));
  EXPECT_TRUE(said.Problems().empty()) << said.Problems().front();

  const TopicQos best_effort{.reliability = Reliability::kBestEffort};
  auto mate = Participant("dyad/qos_test/mate", "mine");
  ASSERT_TRUE(mate);
  ASSERT_TRUE(mate->CreateWriter("t", TypeInfoOf<msg::Counter>(), best_effort).ok());
  ASSERT_TRUE(Await([&] { return !said.Problems().empty(); })) << "this run's incompatible writer is not reported";
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const auto problems = said.Problems();
  ASSERT_EQ(problems.size(), 1u) << problems.back();
  EXPECT_EQ(problems[0],
            "topic 't': a writer of 'dyad/qos_test/mate' offers an incompatible reliability and liveliness QoS; "
            "none of its samples will be delivered here");
}

}  // namespace
}  // namespace dyad
