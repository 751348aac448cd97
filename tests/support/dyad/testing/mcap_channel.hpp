// dyad/testing/mcap_channel.hpp: writes samples of a dyad message type into an MCAP file as the
// recorder does (the IDL schema, CDR through the type's Fast DDS support), stamped on a step grid,
// so that tests can hand analyses a recording whose numbers they chose (test code only).
//
//   auto w = dyad::mcap::Writer::Open(path);
//   dyad::testing::McapChannel<dyad::msg::HumanInput> human(*w, "human/input");
//   human.Write(sample, /*step=*/3);   // stamp and log time: t0 + 3 * period
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include <fastdds/rtps/common/SerializedPayload.h>

#include <dyad/message_traits.hpp>
#include <dyad/msg/ros2_types_support.hpp>  // MessageTraits<T>::PubSubType, complete
#include <dyad/msg/types_support.hpp>

#include "dyad/mcap/writer.hpp"

namespace dyad::testing {

template <class T>
class McapChannel {
 public:
  // t0 is not 0 on purpose: an alignment that forgets to subtract it shows.
  McapChannel(mcap::Writer& w, const std::string& topic, int64_t period_ns = 100'000'000, int64_t t0_ns = 1'000'000'000)
      : w_(w), period_ns_(period_ns), t0_ns_(t0_ns) {
    auto schema = w.AddSchema(MessageTraits<T>::kName, "omgidl", MessageTraits<T>::kIdl);
    EXPECT_TRUE(schema.ok());
    auto channel = w.AddChannel(topic, "cdr", *schema);
    EXPECT_TRUE(channel.ok());
    id_ = *channel;
  }
  // `clock_offset_ns`: the writer's clock is that far ahead (a process on another host).
  void Write(T& m, int64_t step, int64_t clock_offset_ns = 0) {
    m.header().stamp_ns(t0_ns_ + step * period_ns_ + clock_offset_ns);
    m.header().sequence_number(++seq_);
    eprosima::fastrtps::rtps::SerializedPayload_t payload(type_.getSerializedSizeProvider(&m)());
    ASSERT_TRUE(type_.serialize(&m, &payload));
    const auto t = static_cast<uint64_t>(m.header().stamp_ns());
    ASSERT_TRUE(w_.Write(id_, static_cast<uint32_t>(seq_), t, t, {payload.data, payload.length}).ok());
  }

 private:
  mcap::Writer& w_;
  int64_t period_ns_, t0_ns_;
  mcap::ChannelId id_ = 0;
  uint64_t seq_ = 0;
  typename MessageTraits<T>::PubSubType type_;
};

}  // namespace dyad::testing
