// Protocol v2 (udp_auth.hpp): signed packets, the key file, the controller's sessions against
// spoofed, modified and replayed packets.
#include "udp_auth.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace dyad::cartesian::udp {
namespace {

const std::string kKey(32, 'k');
const std::string kOtherKey(32, 'x');

CommandPacket Command(uint32_t session, uint32_t sequence, double x) {
  CommandPacket c;
  c.session = session;
  c.sequence = sequence;
  c.stamp_ns = 100;
  c.x = x, c.y = -1, c.z = 0.5;
  return c;
}

TEST(UdpAuth, SignedPacketsRoundTripWithTheirPeer) {
  std::array<uint8_t, kMaxPacket> b{};
  ASSERT_EQ(EncodeSigned(Command(7, 3, 1.5), 99, kKey, b), kCommand2Size);
  EXPECT_EQ(b[4], kVersion2);
  EXPECT_EQ(b[6], kCommand2Size);
  EXPECT_EQ(SignedKind(b.data(), kCommand2Size), kKindCommand);
  CommandPacket c;
  uint32_t peer = 0;
  ASSERT_EQ(DecodeSignedCommand(b.data(), kCommand2Size, kKey, &c, &peer), Decode::kOk);
  EXPECT_EQ(peer, 99u);
  EXPECT_EQ(c.session, 7u);
  EXPECT_EQ(c.sequence, 3u);
  EXPECT_EQ(c.x, 1.5);

  StatePacket s;
  s.session = 5, s.sequence = 8, s.ack = 3, s.x = 2, s.vz = -4;
  ASSERT_EQ(EncodeSigned(s, 7, kKey, b), kState2Size);
  StatePacket d;
  ASSERT_EQ(DecodeSignedState(b.data(), kState2Size, kKey, &d, &peer), Decode::kOk);
  EXPECT_EQ(peer, 7u);
  EXPECT_EQ(d.ack, 3u);
  EXPECT_EQ(d.vz, -4);

  ASSERT_EQ(EncodeSigned(kKindWelcome, HandshakePacket{11, 7}, kKey, b), kHandshakeSize);
  HandshakePacket h;
  ASSERT_EQ(DecodeSignedHandshake(b.data(), kHandshakeSize, kKindWelcome, kKey, &h), Decode::kOk);
  EXPECT_EQ(h.session, 11u);
  EXPECT_EQ(h.peer, 7u);
  EXPECT_EQ(DecodeSignedHandshake(b.data(), kHandshakeSize, kKindHello, kKey, &h), Decode::kBadKind);
}

// Any single byte changed, and the same packet with another key: rejected, never decoded.
TEST(UdpAuth, AModifiedByteOrAnotherKeyIsRejected) {
  std::array<uint8_t, kMaxPacket> good{};
  const size_t n = EncodeSigned(Command(7, 3, 1.5), 99, kKey, good);
  CommandPacket c;
  uint32_t peer = 0;
  for (size_t i = 0; i < n; ++i) {
    for (uint8_t bit : {uint8_t{0x01}, uint8_t{0x80}}) {
      auto bad = good;
      bad[i] ^= bit;
      EXPECT_NE(DecodeSignedCommand(bad.data(), n, kKey, &c, &peer), Decode::kOk) << "byte " << i;
    }
  }
  std::array<uint8_t, kMaxPacket> forged{};
  EncodeSigned(Command(7, 3, 1000), 99, kOtherKey, forged);
  EXPECT_EQ(DecodeSignedCommand(forged.data(), n, kKey, &c, &peer), Decode::kBadMac);
  // Versions do not mix: a v1 packet is not v2, and the other way round.
  std::array<uint8_t, kCommandSize> v1{};
  Encode(Command(7, 3, 1.5), v1);
  EXPECT_EQ(DecodeSignedCommand(v1.data(), v1.size(), kKey, &c, &peer), Decode::kBadVersion);
  EXPECT_EQ(DecodeCommand(good.data(), n, &c), Decode::kBadVersion);
}

TEST(ControllerSessions, FollowsAWelcomedDriverAndRejectsReplays) {
  ControllerSessions s;
  EXPECT_EQ(s.Command(7, 0, 1), ControllerSessions::Verdict::kStaleSession);  // no handshake
  const uint32_t c1 = s.Hello(7);
  EXPECT_NE(c1, 0u);
  EXPECT_EQ(s.Command(7, c1 + 1, 1), ControllerSessions::Verdict::kStaleSession);  // not the session it was welcomed with
  EXPECT_EQ(s.Command(7, c1, 1), ControllerSessions::Verdict::kApplyNewSession);
  EXPECT_EQ(s.Command(7, c1, 2), ControllerSessions::Verdict::kApply);
  EXPECT_EQ(s.Command(7, c1, 2), ControllerSessions::Verdict::kOld);  // replayed
  EXPECT_EQ(s.Command(7, c1, 1), ControllerSessions::Verdict::kOld);  // replayed, older
  // A replayed hello: a session is offered that nobody uses; the current one goes on.
  const uint32_t offered = s.Hello(7);
  EXPECT_NE(offered, c1);
  EXPECT_EQ(s.Command(7, c1, 3), ControllerSessions::Verdict::kApply);
  // A restarted driver (new session, new handshake) takes over; the old pair is dead for good.
  const uint32_t c2 = s.Hello(8);
  EXPECT_EQ(s.Command(8, c2, 1), ControllerSessions::Verdict::kApplyNewSession);
  EXPECT_EQ(s.Command(7, c1, 4), ControllerSessions::Verdict::kStaleSession);
  EXPECT_EQ(s.Command(7, offered, 4), ControllerSessions::Verdict::kStaleSession);
  EXPECT_EQ(s.controller_session(), c2);
}

class KeyFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("dyad_key_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& bytes, std::filesystem::perms mode) {
    const auto p = dir_ / name;
    std::ofstream(p) << bytes;
    std::filesystem::permissions(p, mode);
    return p.string();
  }
  std::filesystem::path dir_;
};

TEST_F(KeyFileTest, ReadsAPrivateKeyAndRefusesTheRest) {
  using std::filesystem::perms;
  const auto good = Write("good", kKey, perms::owner_read | perms::owner_write);
  auto k = ReadKeyFile(good);
  ASSERT_TRUE(k.ok()) << k.status().message();
  EXPECT_EQ(*k, kKey);
  const auto shared = Write("shared", kKey, perms::owner_read | perms::owner_write | perms::group_read | perms::others_read);
  EXPECT_NE(ReadKeyFile(shared).status().message().find(shared + ": readable or writable by others"), std::string::npos);
  const auto short_key = Write("short", "12345", perms::owner_read);
  EXPECT_NE(ReadKeyFile(short_key).status().message().find("shorter than 32 bytes"), std::string::npos);
  std::filesystem::create_symlink(good, dir_ / "link");
  EXPECT_NE(ReadKeyFile((dir_ / "link").string()).status().message().find("symbolic link"), std::string::npos);
  EXPECT_FALSE(ReadKeyFile((dir_ / "missing").string()).ok());
}

}  // namespace
}  // namespace dyad::cartesian::udp
