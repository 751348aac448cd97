// Fuzz target: the UDP robot protocol parser (datagrams from a controller or a driver). A packet
// that decodes re-encodes to the same bytes.
#include <array>
#include <cstring>

#include "fuzz_support.hpp"
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
  return 0;
}
