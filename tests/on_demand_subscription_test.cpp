// On-demand serialized subscriptions on Fast DDS (dyad/on_demand_subscription.hpp): no reader
// before the first Start(), samples only while started, the newest `depth` kept while stopped.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

#include <dyad/decode_sample.hpp>
#include <dyad/msg/types.hpp>

#include "dds/dds_participant.hpp"
#include "dyad/testing/dds_domain.hpp"

namespace dyad {
namespace {

using std::chrono::milliseconds;

class ZeroClock final : public Clock {
 public:
  int64_t now_ns() const override { return 0; }
};

class OnDemandOnFastDds : public ::testing::Test {
 protected:
  void SetUp() override {
    DdsParticipant::Options o;
    o.scope = DdsParticipant::Scope::kProcessOnly;
    o.partitions = {"dyad/on_demand_test"};
    auto p = DdsParticipant::Create(testing::DomainForThisProcess(), "on_demand", std::move(o));
    ASSERT_TRUE(p.ok()) << p.status().message();
    participant_ = std::move(p.value());
    const TopicQos qos{.reliability = Reliability::kReliable, .depth = 1};
    auto w = participant_->CreateWriter("t", TypeInfoOf<msg::Counter>(), qos);
    auto r = participant_->CreateOnDemandReader("t", TypeInfoOf<msg::Counter>(), qos, &clock_,
                                                [this](const SerializedSample& s) {
                                                  msg::Counter c;
                                                  ASSERT_TRUE(DecodeSample(s.cdr, &c).ok());
                                                  std::lock_guard<std::mutex> lock(mutex_);
                                                  got_.push_back(c.value());
                                                });
    ASSERT_TRUE(w.ok() && r.ok());
    writer_ = w.value();
    reader_ = r.value();
  }
  void Write(int64_t value) {
    msg::Counter c;
    c.value(value);
    ASSERT_TRUE(writer_->Write(&c).ok());
  }
  std::vector<int64_t> Got() {
    std::lock_guard<std::mutex> lock(mutex_);
    return got_;
  }
  // Waits (5 s at most) until the writer has matched `n` readers.
  bool AwaitWriterMatched(int n) {
    for (int i = 0; i < 1000 && writer_->matched() != n; ++i) std::this_thread::sleep_for(milliseconds(5));
    return writer_->matched() == n;
  }
  bool AwaitGot(size_t n) {
    for (int i = 0; i < 1000 && Got().size() < n; ++i) std::this_thread::sleep_for(milliseconds(5));
    return Got().size() >= n;
  }

  ZeroClock clock_;
  std::unique_ptr<DdsParticipant> participant_;
  TypedWriter* writer_ = nullptr;    // owned by participant_
  OnDemandReader* reader_ = nullptr;  // owned by participant_
  std::mutex mutex_;
  std::vector<int64_t> got_;
};

TEST_F(OnDemandOnFastDds, HasNoReaderBeforeTheFirstStart) {
  for (const auto& e : participant_->Matches()) EXPECT_TRUE(e.writer) << "a reader on '" << e.topic << "' before Start()";
  std::this_thread::sleep_for(milliseconds(200));  // discovery would have matched one by now
  EXPECT_EQ(writer_->matched(), 0);
  Write(1);
  EXPECT_TRUE(Got().empty());
  EXPECT_FALSE(reader_->started());
}

TEST_F(OnDemandOnFastDds, DeliversWhileStartedAndKeepsOnlyTheNewestWhileStopped) {
  ASSERT_TRUE(reader_->Start().ok());
  ASSERT_TRUE(AwaitWriterMatched(1));
  Write(1);
  ASSERT_TRUE(AwaitGot(1));
  reader_->Stop();
  Write(2);
  Write(3);
  std::this_thread::sleep_for(milliseconds(100));
  EXPECT_EQ(Got(), (std::vector<int64_t>{1})) << "called back while stopped";
  EXPECT_EQ(writer_->matched(), 1) << "the reader stays while stopped";
  ASSERT_TRUE(reader_->Start().ok());  // the newest kept (depth 1) comes first
  Write(4);
  ASSERT_TRUE(AwaitGot(3));
  EXPECT_EQ(Got(), (std::vector<int64_t>{1, 3, 4}));
  EXPECT_EQ(reader_->delivered(), 3u);
}

TEST_F(OnDemandOnFastDds, CannotStartOnceClosed) {
  reader_->Close();
  EXPECT_EQ(reader_->Start().code(), Status::Code::kFailedPrecondition);
}

}  // namespace
}  // namespace dyad
