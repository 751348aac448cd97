/// The dyad Cartesian UDP protocol, version 1: one datagram per message, little-endian, fixed
/// sizes, no allocation, no authentication (version 2, udp_auth.hpp, adds it). Specified in docs/components.md (## udp_cartesian); this header is its
/// executable form, shared by the `udp_cartesian` driver and `dyad_fake_controller`.
///
/// Every packet starts with a 16-byte header:
///   0  u32 magic    0x43525944 (the bytes "DYRC")
///   4  u8  version  1
///   5  u8  kind     1 = command (driver -> controller), 2 = state (controller -> driver)
///   6  u16 length   total packet length in bytes (56 for a command, 80 for a state)
///   8  u32 session  random, non-zero, drawn by the sender when it starts; a packet of another
///                   session than the receiver's current one starts a new session (sequence
///                   checks begin afresh): a restarted driver or controller is followed at once
///  12  u32 sequence per sender and session, starting at 1, +1 per packet sent
/// Command (kind 1), after the header:
///  16  i64 stamp_ns driver's runtime clock when the command was sent
///  24  f64 x, 32 f64 y, 40 f64 z   target position, workspace units
///  48  u32 flags    bit 0: hold: stay, keep the current target, never move to x, y, z (the
///                   mixer holds: stale inputs, a lost arm, or waiting for the arm's first
///                   state; x, y, z are the position held, docs/components.md "The command
///                   contract")
///  52  u32 reserved 0
/// State (kind 2), after the header:
///  16  u32 ack      sequence of the newest command the controller has applied (0: none yet)
///  20  u32 flags    bit 0: stopped (controller watchdog or limit stop)
///  24  i64 stamp_ns the applied command's stamp_ns (the time this state belongs to)
///  32  f64 x, 40 f64 y, 48 f64 z, 56 f64 vx, 64 f64 vy, 72 f64 vz   measured, units and units/s
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace dyad::cartesian::udp {

inline constexpr uint32_t kMagic = 0x43525944;  // "DYRC" in memory order
inline constexpr uint8_t kVersion = 1;
inline constexpr uint8_t kKindCommand = 1;
inline constexpr uint8_t kKindState = 2;
inline constexpr size_t kHeaderSize = 16;
inline constexpr size_t kCommandSize = 56;
inline constexpr size_t kStateSize = 80;
inline constexpr size_t kMaxPacket = 128;  // receive buffer; anything longer is malformed
inline constexpr uint32_t kFlagHold = 1;
inline constexpr uint32_t kFlagStopped = 1;

struct CommandPacket {
  uint32_t session = 0;
  uint32_t sequence = 0;
  int64_t stamp_ns = 0;
  double x = 0, y = 0, z = 0;
  bool hold = false;
};

struct StatePacket {
  uint32_t session = 0;
  uint32_t sequence = 0;
  uint32_t ack = 0;
  bool stopped = false;
  int64_t stamp_ns = 0;
  double x = 0, y = 0, z = 0, vx = 0, vy = 0, vz = 0;
};

// Why a datagram was rejected.
enum class Decode { kOk, kTooShort, kBadMagic, kBadVersion, kBadKind, kBadLength, kNotFinite, kBadMac };
const char* ToString(Decode d);

void Encode(const CommandPacket& p, std::array<uint8_t, kCommandSize>& out);
void Encode(const StatePacket& p, std::array<uint8_t, kStateSize>& out);
// Check the header (magic, version, kind, length == size == the kind's size), then fill *out;
// kNotFinite when a position or velocity is NaN or infinite (*out is filled all the same).
Decode DecodeCommand(const uint8_t* data, size_t size, CommandPacket* out);
Decode DecodeState(const uint8_t* data, size_t size, StatePacket* out);

// A random non-zero session number.
uint32_t NewSession();

// True when sequence `a` is newer than `b` (serial-number arithmetic: survives the u32 wrap).
inline bool Newer(uint32_t a, uint32_t b) { return static_cast<int32_t>(a - b) > 0; }

}  // namespace dyad::cartesian::udp

namespace dyad::cartesian::udp {

// The driver's bookkeeping of incoming states: which to accept, and what went wrong.
// Pure; tested in test/udp_protocol_test.cpp.
class StateTracker {
 public:
  enum class Verdict { kAccepted, kAcceptedLate, kOutOfOrder };
  struct Counts {
    uint64_t accepted = 0;      // states taken (including late ones)
    uint64_t late = 0;          // accepted, but not the reply awaited at the time (it missed its own wait)
    uint64_t out_of_order = 0;  // dropped: not newer than the newest accepted (or a duplicate)
    uint64_t gaps = 0;          // controller sequence numbers never seen (states lost on the way)
    uint64_t malformed = 0;     // dropped: failed to decode (counted by the caller via Malformed())
    uint64_t sessions = 0;      // controller sessions seen (more than 1: the controller restarted)
  };

  // A decoded state arrived while the driver was waiting for the reply to command `awaiting`
  // (0: not waiting, between steps).
  Verdict Offer(const StatePacket& s, uint32_t awaiting) {
    if (!has_ || s.session != session_) {  // first state, or a restarted controller
      has_ = true;
      session_ = s.session;
      ++counts_.sessions;
    } else if (!Newer(s.sequence, newest_)) {
      ++counts_.out_of_order;
      return Verdict::kOutOfOrder;
    } else {
      counts_.gaps += s.sequence - newest_ - 1;
    }
    newest_ = s.sequence;
    ++counts_.accepted;
    if (s.ack != awaiting) {
      ++counts_.late;
      return Verdict::kAcceptedLate;
    }
    return Verdict::kAccepted;
  }
  void Malformed() { ++counts_.malformed; }
  const Counts& counts() const { return counts_; }

 private:
  bool has_ = false;
  uint32_t session_ = 0;
  uint32_t newest_ = 0;
  Counts counts_;
};

}  // namespace dyad::cartesian::udp
