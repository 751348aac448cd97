// Fuzz target: the UDP robot protocol parser (datagrams from a controller or a driver), version 1
// and version 2 (signed, with a fixed key). A packet that decodes re-encodes to the same bytes.
#include <array>
#include <cstring>
#include <string>

#include "fuzz_support.hpp"
#include "udp_auth.hpp"
#include "udp_protocol.hpp"

namespace udp = dyad::cartesian::udp;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  udp::CommandPacket command;
  if (udp::DecodeCommand(data, size, &command) == udp::Decode::kOk) {
    std::array<uint8_t, udp::kCommandSize> again{};
    udp::Encode(command, again);
    udp::CommandPacket back;
    dyad::fuzz::Require(udp::DecodeCommand(again.data(), again.size(), &back) == udp::Decode::kOk &&
                            back.sequence == command.sequence && back.x == command.x && back.hold == command.hold,
                        "command does not survive a re-encode");
  }
  udp::StatePacket state;
  const udp::Decode d = udp::DecodeState(data, size, &state);
  dyad::fuzz::Require(udp::ToString(d) != nullptr, "Decode without a name");
  if (d == udp::Decode::kOk) {
    std::array<uint8_t, udp::kStateSize> again{};
    udp::Encode(state, again);
    udp::StatePacket back;
    dyad::fuzz::Require(udp::DecodeState(again.data(), again.size(), &back) == udp::Decode::kOk &&
                            back.ack == state.ack && back.vz == state.vz && back.stopped == state.stopped,
                        "state does not survive a re-encode");
  }
  // Version 2: the header and MAC checks come first; whatever passes them re-signs identically.
  const std::string key(32, 'k');
  uint32_t peer = 0;
  std::array<uint8_t, udp::kMaxPacket> again{};
  if (udp::DecodeSignedCommand(data, size, key, &command, &peer) == udp::Decode::kOk)
    dyad::fuzz::Require(udp::EncodeSigned(command, peer, key, again) == size && std::memcmp(again.data(), data, size) == 0,
                        "signed command does not survive a re-encode");
  if (udp::DecodeSignedState(data, size, key, &state, &peer) == udp::Decode::kOk)
    dyad::fuzz::Require(udp::EncodeSigned(state, peer, key, again) == size, "signed state does not survive a re-encode");
  udp::HandshakePacket hello;
  (void)udp::DecodeSignedHandshake(data, size, udp::SignedKind(data, size), key, &hello);
  return 0;
}
