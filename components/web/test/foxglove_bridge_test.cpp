// FoxgloveBridge without a server: each channel's subscription is started by its first client
// subscription and stopped by the last one's end (unsubscribe or close), as foxglove_bridge does.
#include "foxglove_bridge.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace dyad::web {
namespace {

// Counts what the bridge asks of a channel's subscription.
class FakeSubscription final : public OnDemandSubscription {
 public:
  explicit FakeSubscription(std::string topic, Status start = Status::OK()) : topic_(std::move(topic)), start_(start) {}
  const std::string& topic() const override { return topic_; }
  Status Start() override {
    ++starts;
    if (start_.ok()) started_ = true;
    return start_;
  }
  void Stop() override {
    ++stops;
    started_ = false;
  }
  bool started() const override { return started_; }
  int starts = 0, stops = 0;

 private:
  std::string topic_;
  Status start_;
  bool started_ = false;
};

std::string Subscribe(uint32_t id, uint32_t channel) {
  return R"({"op":"subscribe","subscriptions":[{"id":)" + std::to_string(id) + R"(,"channelId":)" + std::to_string(channel) + "}]}";
}
std::string Unsubscribe(uint32_t id) { return R"({"op":"unsubscribe","subscriptionIds":[)" + std::to_string(id) + "]}"; }

class FoxgloveBridgeTest : public ::testing::Test {
 protected:
  FoxgloveBridgeTest() : bridge_("test", {{1, "a", "T", ""}, {2, "b", "T", ""}}, {}), a_("a"), b_("b") {
    bridge_.SetSubscription(1, &a_);
    bridge_.SetSubscription(2, &b_);
  }
  FoxgloveBridge bridge_;
  FakeSubscription a_, b_;
};

TEST_F(FoxgloveBridgeTest, NothingIsReadBeforeAClientSubscribes) {
  bridge_.OnOpen(1, Role::kExperimenter);
  EXPECT_EQ(a_.starts + b_.starts, 0);
  EXPECT_FALSE(a_.started());
  EXPECT_FALSE(b_.started());
}

TEST_F(FoxgloveBridgeTest, TheFirstSubscriptionStartsAChannelAndTheLastUnsubscribeStopsIt) {
  bridge_.OnOpen(1, Role::kExperimenter);
  bridge_.OnOpen(2, Role::kExperimenter);
  ASSERT_TRUE(bridge_.OnText(1, Subscribe(10, 1)).ok());
  EXPECT_TRUE(a_.started());
  EXPECT_FALSE(b_.started());
  ASSERT_TRUE(bridge_.OnText(2, Subscribe(20, 1)).ok());
  EXPECT_EQ(a_.starts, 1);
  ASSERT_TRUE(bridge_.OnText(1, Unsubscribe(10)).ok());
  EXPECT_TRUE(a_.started()) << "client 2 still watches";
  ASSERT_TRUE(bridge_.OnText(2, Unsubscribe(20)).ok());
  EXPECT_FALSE(a_.started());
  EXPECT_EQ(a_.stops, 1);
  ASSERT_TRUE(bridge_.OnText(1, Subscribe(11, 1)).ok());
  EXPECT_TRUE(a_.started());
  EXPECT_EQ(a_.starts, 2);
}

TEST_F(FoxgloveBridgeTest, ClosingTheLastWatchingClientStopsItsChannels) {
  bridge_.OnOpen(1, Role::kExperimenter);
  bridge_.OnOpen(2, Role::kExperimenter);
  ASSERT_TRUE(bridge_.OnText(1, Subscribe(1, 1)).ok());
  ASSERT_TRUE(bridge_.OnText(1, Subscribe(2, 2)).ok());
  ASSERT_TRUE(bridge_.OnText(2, Subscribe(1, 2)).ok());
  bridge_.OnClose(1);
  EXPECT_FALSE(a_.started());
  EXPECT_TRUE(b_.started()) << "client 2 still watches b";
  bridge_.OnClose(2);
  EXPECT_FALSE(b_.started());
  EXPECT_EQ(a_.stops + b_.stops, 2);
}

TEST(FoxgloveBridge, ASubscriptionThatCannotStartIsRetriedByTheNextSubscriber) {
  FakeSubscription broken("a", Status::Internal("cannot create reader on topic 'a'"));
  FoxgloveBridge bridge("test", {{1, "a", "T", ""}}, {});
  bridge.SetSubscription(1, &broken);
  bridge.OnOpen(1, Role::kExperimenter);
  ASSERT_TRUE(bridge.OnText(1, Subscribe(1, 1)).ok());  // reported to the client, not fatal
  ASSERT_TRUE(bridge.OnText(1, Subscribe(2, 1)).ok());
  EXPECT_EQ(broken.starts, 2);
  EXPECT_FALSE(broken.started());
}

// A client cannot grow the server's tables: its subscriptions past the cap are refused.
TEST_F(FoxgloveBridgeTest, AClientHoldsAtMostTheCappedNumberOfSubscriptions) {
  bridge_.OnOpen(1, Role::kViewer);
  std::string many = R"({"op":"subscribe","subscriptions":[)";
  for (uint32_t id = 1; id <= 3000; ++id) {
    if (id > 1) many += ',';
    many.append(R"({"id":)").append(std::to_string(id)).append(R"(,"channelId":1})");
  }
  many += "]}";
  ASSERT_TRUE(bridge_.OnText(1, many).ok());
  const uint8_t cdr[] = {0, 1, 0, 0};
  bridge_.OnSample(1, SerializedSample{cdr, 0, 0, 1});  // counted per route, even with no server
  EXPECT_EQ(bridge_.samples_sent(), FoxgloveBridge::kMaxSubscriptions);
}

// Counts the samples a client managed to publish.
class CountingWriter final : public SerializedWriter {
 public:
  const std::string& topic() const override { return topic_; }
  const TypeInfo& type() const override { return *type_; }
  Status Write(std::span<const uint8_t>, int64_t) override {
    ++writes_;
    return Status::OK();
  }
  uint64_t written() const override { return writes_; }

 private:
  std::string topic_ = "w";
  const TypeInfo* type_ = nullptr;
  uint64_t writes_ = 0;
};

// Publishing needs the experimenter's token: a viewer's advertisement is refused, and what it
// then sends on that channel never reaches the writer.
TEST(FoxgloveBridge, OnlyTheExperimenterMayPublish) {
  CountingWriter writer;
  FoxgloveBridge bridge("test", {{1, "w", "T", ""}}, {{"w", &writer}});
  const std::string advertise = R"({"op":"advertise","channels":[{"id":7,"topic":"w","encoding":"cdr","schemaName":"T"}]})";
  const uint8_t frame[] = {0x01, 7, 0, 0, 0, 0, 1, 0, 0};  // Message Data on client channel 7: a CDR header
  for (Role role : {Role::kViewer, Role::kSubject, Role::kExperimenter}) {
    const ClientId id = static_cast<ClientId>(role) + 1;
    bridge.OnOpen(id, role);
    ASSERT_TRUE(bridge.OnText(id, advertise).ok());
    ASSERT_TRUE(bridge.OnBinary(id, frame).ok());
  }
  EXPECT_EQ(writer.written(), 1u) << "only the experimenter's sample";
}

}  // namespace
}  // namespace dyad::web
