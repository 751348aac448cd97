// Input/Output ports against fake endpoints: what a component sees between steps.
#include <gtest/gtest.h>

#include <deque>

#include <dyad/component.hpp>
#include <dyad/msg/types.hpp>

namespace dyad {
namespace {

class FakeReader : public detail::ReaderEndpoint {
 public:
  bool TakeNext(void* sample) override {
    if (queue.empty()) return false;
    *static_cast<msg::Counter*>(sample) = queue.front();
    queue.pop_front();
    return true;
  }
  std::deque<msg::Counter> queue;
};

class FakeWriter : public detail::WriterEndpoint {
 public:
  Status Write(const void* sample) override {
    written.push_back(*static_cast<const msg::Counter*>(sample));
    return Status::OK();
  }
  std::vector<msg::Counter> written;
};

class FixedClock : public Clock {
 public:
  int64_t now_ns() const override { return t; }
  int64_t t = 0;
};

msg::Counter Make(int64_t v) {
  msg::Counter c;
  c.value(v);
  return c;
}

TEST(InputPort, ReceivedHoldsOnlyThisPollAndLatestSurvivesEmptyPolls) {
  FakeReader reader;
  Input<msg::Counter> in;
  in.Bind("in", "count", &reader);
  EXPECT_EQ(in.latest(), nullptr);
  EXPECT_EQ(in.Poll(5), 0u);
  EXPECT_EQ(in.last_receive_ns(), -1);

  reader.queue = {Make(1), Make(2), Make(3)};
  ASSERT_EQ(in.Poll(10), 3u);
  ASSERT_EQ(in.received().size(), 3u);
  EXPECT_EQ(in.received()[0].value(), 1);
  EXPECT_EQ(in.received()[2].value(), 3);
  EXPECT_EQ(in.latest()->value(), 3);
  EXPECT_EQ(in.last_receive_ns(), 10);

  EXPECT_EQ(in.Poll(20), 0u);  // nothing new: received() empties, latest() stays
  EXPECT_TRUE(in.received().empty());
  EXPECT_EQ(in.new_count(), 0u);
  ASSERT_NE(in.latest(), nullptr);
  EXPECT_EQ(in.latest()->value(), 3);
  EXPECT_EQ(in.last_receive_ns(), 10);

  reader.queue = {Make(4)};
  in.Poll(30);
  EXPECT_EQ(in.latest()->value(), 4);
}

TEST(InputPort, UnboundInputReceivesNothing) {
  Input<msg::Counter> in;
  EXPECT_FALSE(in.bound());
  EXPECT_EQ(in.Poll(1), 0u);
  EXPECT_EQ(in.latest(), nullptr);
}

TEST(OutputPort, PublishFillsHeader) {
  FakeWriter writer;
  FixedClock clock;
  Output<msg::Counter> out;
  out.Bind("out", "count", "src", &writer, &clock);
  msg::Counter c = Make(7);
  clock.t = 100;
  ASSERT_TRUE(out.Publish(c).ok());
  clock.t = 200;
  ASSERT_TRUE(out.Publish(c).ok());
  ASSERT_EQ(writer.written.size(), 2u);
  EXPECT_EQ(writer.written[0].header().source(), "src");
  EXPECT_EQ(writer.written[0].header().sequence_number(), 1u);
  EXPECT_EQ(writer.written[0].header().stamp_ns(), 100);
  EXPECT_EQ(writer.written[1].header().sequence_number(), 2u);
  EXPECT_EQ(writer.written[1].header().stamp_ns(), 200);
  EXPECT_EQ(out.published(), 2u);
}

TEST(OutputPort, UnboundOutputDropsButCounts) {
  Output<msg::Counter> out;
  msg::Counter c = Make(1);
  EXPECT_TRUE(out.Publish(c).ok());
  EXPECT_EQ(out.published(), 1u);
}

}  // namespace
}  // namespace dyad
