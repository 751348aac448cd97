// The UDP protocol: byte layout (little-endian, as documented), rejection of malformed packets,
// sequence bookkeeping.
#include "udp_protocol.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include <cstring>

namespace dyad::cartesian::udp {
namespace {

TEST(UdpProtocol, CommandLayoutIsTheDocumentedLittleEndianOne) {
  CommandPacket c;
  c.session = 0xA1B2C3D4;
  c.sequence = 0x01020304;
  c.stamp_ns = 0x1122334455667788;
  c.x = 1.5, c.y = -2.0, c.z = 0.25;
  c.hold = true;
  std::array<uint8_t, kCommandSize> b{};
  Encode(c, b);
  const uint8_t head[16] = {'D', 'Y', 'R', 'C', 1, 1, 56, 0, 0xD4, 0xC3, 0xB2, 0xA1, 4, 3, 2, 1};
  EXPECT_EQ(std::memcmp(b.data(), head, 16), 0);
  EXPECT_EQ(b[16], 0x88);
  EXPECT_EQ(b[23], 0x11);
  const uint8_t x15[8] = {0, 0, 0, 0, 0, 0, 0xF8, 0x3F};  // 1.5 as IEEE 754 little-endian
  EXPECT_EQ(std::memcmp(b.data() + 24, x15, 8), 0);
  EXPECT_EQ(b[48], 1);  // hold
  CommandPacket d;
  ASSERT_EQ(DecodeCommand(b.data(), b.size(), &d), Decode::kOk);
  EXPECT_EQ(d.session, c.session);
  EXPECT_EQ(d.sequence, c.sequence);
  EXPECT_EQ(d.stamp_ns, c.stamp_ns);
  EXPECT_EQ(d.x, 1.5);
  EXPECT_EQ(d.y, -2.0);
  EXPECT_EQ(d.z, 0.25);
  EXPECT_TRUE(d.hold);
}

TEST(UdpProtocol, StateRoundTrips) {
  StatePacket s;
  s.session = 9, s.sequence = 7, s.ack = 6, s.stopped = true, s.stamp_ns = -5;
  s.x = 1, s.y = 2, s.z = 3, s.vx = 4, s.vy = 5, s.vz = 6;
  std::array<uint8_t, kStateSize> b{};
  Encode(s, b);
  EXPECT_EQ(b[5], kKindState);
  EXPECT_EQ(b[6], 80);
  StatePacket d;
  ASSERT_EQ(DecodeState(b.data(), b.size(), &d), Decode::kOk);
  EXPECT_EQ(d.session, 9u);
  EXPECT_EQ(d.sequence, 7u);
  EXPECT_EQ(d.ack, 6u);
  EXPECT_TRUE(d.stopped);
  EXPECT_EQ(d.stamp_ns, -5);
  EXPECT_EQ(d.vz, 6);
}

TEST(UdpProtocol, MalformedPacketsAreRejectedWithTheReason) {
  StatePacket s;
  std::array<uint8_t, kStateSize> b{};
  Encode(s, b);
  StatePacket d;
  EXPECT_EQ(DecodeState(b.data(), 10, &d), Decode::kTooShort);
  EXPECT_EQ(DecodeState(b.data(), 79, &d), Decode::kBadLength);
  auto bad = b;
  bad[0] ^= 0xFF;
  EXPECT_EQ(DecodeState(bad.data(), bad.size(), &d), Decode::kBadMagic);
  bad = b;
  bad[4] = 2;
  EXPECT_EQ(DecodeState(bad.data(), bad.size(), &d), Decode::kBadVersion);
  bad = b;
  bad[6] = 81;
  EXPECT_EQ(DecodeState(bad.data(), bad.size(), &d), Decode::kBadLength);
  // A command is not a state.
  std::array<uint8_t, kCommandSize> c{};
  Encode(CommandPacket(), c);
  EXPECT_EQ(DecodeState(c.data(), c.size(), &d), Decode::kBadKind);
}

// A controller that reports a NaN position (or a driver that sends one) is faulty: the packet is
// dropped as malformed rather than published to the deliberator or applied to the robot.
TEST(UdpProtocol, NonFiniteNumbersAreMalformed) {
  StatePacket s;
  s.vy = std::nan("");
  std::array<uint8_t, kStateSize> b{};
  Encode(s, b);
  StatePacket d;
  EXPECT_EQ(DecodeState(b.data(), b.size(), &d), Decode::kNotFinite);
  CommandPacket c;
  c.z = INFINITY;
  std::array<uint8_t, kCommandSize> cb{};
  Encode(c, cb);
  CommandPacket dc;
  EXPECT_EQ(DecodeCommand(cb.data(), cb.size(), &dc), Decode::kNotFinite);
  EXPECT_STREQ(ToString(Decode::kNotFinite), "a number is NaN or infinite");
}

TEST(UdpProtocol, SequenceComparisonSurvivesWrapAround) {
  EXPECT_TRUE(Newer(2, 1));
  EXPECT_FALSE(Newer(1, 1));
  EXPECT_FALSE(Newer(1, 2));
  EXPECT_TRUE(Newer(0, 0xFFFFFFFF));
  EXPECT_TRUE(Newer(5, 0xFFFFFFF0));
}

StatePacket State(uint32_t seq, uint32_t ack, uint32_t session = 1) {
  StatePacket s;
  s.session = session;
  s.sequence = seq;
  s.ack = ack;
  return s;
}

TEST(StateTracker, CountsLateLostAndOutOfOrder) {
  StateTracker t;
  using V = StateTracker::Verdict;
  EXPECT_EQ(t.Offer(State(1, 1), 1), V::kAccepted);
  EXPECT_EQ(t.Offer(State(2, 2), 3), V::kAcceptedLate);  // reply to command 2 while 3 is out
  EXPECT_EQ(t.Offer(State(4, 4), 4), V::kAccepted);       // state 3 never came
  EXPECT_EQ(t.Offer(State(3, 3), 4), V::kOutOfOrder);     // ... until now: too old
  EXPECT_EQ(t.Offer(State(4, 4), 4), V::kOutOfOrder);     // duplicate
  t.Malformed();
  const auto& c = t.counts();
  EXPECT_EQ(c.accepted, 3u);
  EXPECT_EQ(c.late, 1u);
  EXPECT_EQ(c.gaps, 1u);
  EXPECT_EQ(c.out_of_order, 2u);
  EXPECT_EQ(c.malformed, 1u);
  EXPECT_EQ(c.sessions, 1u);
}

TEST(StateTracker, ARestartedControllerStartsANewSession) {
  StateTracker t;
  using V = StateTracker::Verdict;
  EXPECT_EQ(t.Offer(State(500, 500, 1), 500), V::kAccepted);
  EXPECT_EQ(t.Offer(State(1, 501, 2), 501), V::kAccepted);  // sequence 1 again: new session, not out of order
  EXPECT_EQ(t.Offer(State(2, 502, 2), 502), V::kAccepted);
  EXPECT_EQ(t.counts().sessions, 2u);
  EXPECT_EQ(t.counts().gaps, 0u);
  EXPECT_EQ(t.counts().out_of_order, 0u);
}

}  // namespace
}  // namespace dyad::cartesian::udp
