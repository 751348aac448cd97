/// The dyad Cartesian UDP protocol, version 2: version 1's messages, authenticated. Specified in
/// docs/components.md (## udp_cartesian, "Protocol version 2"); shared by `udp_cartesian` (with
/// `key_file`) and `dyad_fake_controller --key-file`.
///
/// Every v2 packet is a v1 packet with version 2, a 4-byte `peer` field after the header (the
/// other side's session this packet belongs to) and a 32-byte HMAC-SHA256 trailer over all the
/// bytes before it, keyed with a pre-shared key (a file of at least 32 bytes, readable by its
/// owner only):
///   0  header (16 bytes, as v1; version 2; length = the whole v2 packet)
///  16  u32 peer     command: the controller session it was welcomed with; state: the driver's
///                   session; hello: 0; welcome: the driver session it answers
///  20  body         v1's body (command: 40 bytes, state: 64 bytes; hello and welcome: none)
///  ..  32 bytes     HMAC-SHA256(key, bytes 0 .. length-33)
/// Kinds: 1 command (92 bytes), 2 state (116), 3 hello (52: driver -> controller), 4 welcome (52).
///
/// Sessions. A driver session starts with a handshake: the driver sends hello (its new random
/// session), the controller answers welcome with a fresh random session of its own for that
/// hello. Commands carry both (session = driver's, peer = controller's); the controller applies
/// a command only when the pair is the current one, or the one it welcomed last (which then
/// becomes current: a restarted driver), and only when its sequence is newer than the last
/// applied. So: a packet without the key is rejected (its MAC), a modified one too, a replayed
/// one is older than the last applied or belongs to a pair that is no longer current, and a
/// replayed hello only makes the controller draw a session nobody uses. States carry
/// (controller's, driver's) and the driver accepts only its current pair.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <dyad/status.hpp>

#include "udp_protocol.hpp"

namespace dyad::cartesian::udp {

inline constexpr uint8_t kVersion2 = 2;
inline constexpr uint8_t kKindHello = 3;
inline constexpr uint8_t kKindWelcome = 4;
inline constexpr size_t kMacSize = 32;
inline constexpr size_t kHeader2Size = kHeaderSize + 4;
inline constexpr size_t kCommand2Size = kCommandSize + 4 + kMacSize;  // 92
inline constexpr size_t kState2Size = kStateSize + 4 + kMacSize;      // 116
inline constexpr size_t kHandshakeSize = kHeader2Size + kMacSize;     // 52
inline constexpr size_t kMinKeySize = 32;
static_assert(kState2Size <= kMaxPacket);

// A hello (driver -> controller) or welcome (controller -> driver).
struct HandshakePacket {
  uint32_t session = 0;  // the sender's
  uint32_t peer = 0;     // welcome: the driver session it answers; hello: 0
};

// The pre-shared key: the file's bytes. Refused (InvalidArgument naming the path): missing, not a
// regular file, a symlink, readable or writable by group or others, shorter than kMinKeySize.
StatusOr<std::string> ReadKeyFile(const std::string& path);

// Encoders: the v2 packet into `out`; return its size (0 if OpenSSL failed: send nothing). `peer`: see above.
size_t EncodeSigned(const CommandPacket& p, uint32_t peer, std::string_view key, std::array<uint8_t, kMaxPacket>& out);
size_t EncodeSigned(const StatePacket& p, uint32_t peer, std::string_view key, std::array<uint8_t, kMaxPacket>& out);
size_t EncodeSigned(uint8_t kind, const HandshakePacket& p, std::string_view key, std::array<uint8_t, kMaxPacket>& out);

// The kind byte of a v2 packet (0 when it is too short or not v2): which decoder to call.
uint8_t SignedKind(const uint8_t* data, size_t size);

// Decoders: the header (magic, version 2, kind, length), then the MAC (kBadMac: a wrong key or a
// modified byte; compared in constant time), then the body as v1 does (kNotFinite ...).
Decode DecodeSignedCommand(const uint8_t* data, size_t size, std::string_view key, CommandPacket* out, uint32_t* peer);
Decode DecodeSignedState(const uint8_t* data, size_t size, std::string_view key, StatePacket* out, uint32_t* peer);
Decode DecodeSignedHandshake(const uint8_t* data, size_t size, uint8_t kind, std::string_view key, HandshakePacket* out);

// The controller's side of the sessions (pure; see the file comment).
class ControllerSessions {
 public:
  enum class Verdict {
    kApply,            // the current pair, a newer sequence
    kApplyNewSession,  // the pair welcomed last, now current (a new or restarted driver)
    kStaleSession,     // a pair that is not (or no longer) current: rejected
    kOld,              // the current pair, but not newer than the last applied: a replay or late
  };
  // An authenticated hello: the controller session to welcome this driver session with.
  uint32_t Hello(uint32_t driver_session);
  // An authenticated command.
  Verdict Command(uint32_t driver_session, uint32_t controller_session, uint32_t sequence);
  uint32_t controller_session() const { return current_controller_; }
  uint32_t driver_session() const { return current_driver_; }

 private:
  uint32_t current_driver_ = 0, current_controller_ = 0;
  uint32_t offered_driver_ = 0, offered_controller_ = 0;
  bool has_applied_ = false;
  uint32_t applied_ = 0;
};

}  // namespace dyad::cartesian::udp
