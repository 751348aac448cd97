#include "udp_auth.hpp"

#include <fcntl.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace dyad::cartesian::udp {

namespace {

// False when OpenSSL fails (never seen): a packet is then neither signed nor accepted.
bool Mac(std::string_view key, const uint8_t* data, size_t size, uint8_t* mac) {
  unsigned int length = 0;
  return HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), data, size, mac, &length) != nullptr &&
         length == kMacSize;
}

// v1 image <-> v2 packet: the v1 header and body around the peer field, then the MAC.
size_t Sign(const uint8_t* v1, size_t v1_size, uint32_t peer, std::string_view key, std::array<uint8_t, kMaxPacket>& out) {
  const size_t size = v1_size + 4 + kMacSize;
  std::memcpy(out.data(), v1, kHeaderSize);
  out[4] = kVersion2;
  out[6] = static_cast<uint8_t>(size & 0xff);
  out[7] = static_cast<uint8_t>(size >> 8);
  for (int i = 0; i < 4; ++i) out[kHeaderSize + i] = static_cast<uint8_t>(peer >> (8 * i));
  std::memcpy(out.data() + kHeader2Size, v1 + kHeaderSize, v1_size - kHeaderSize);
  if (!Mac(key, out.data(), size - kMacSize, out.data() + size - kMacSize)) return 0;  // nothing to send
  return size;
}

// Checks a v2 packet of `kind` and `expected` size and its MAC; on success the v1 image of its
// header and body is in `v1` (for v1's decoders) and its peer in *peer.
Decode Verify(const uint8_t* p, size_t size, uint8_t kind, size_t expected, std::string_view key,
              std::array<uint8_t, kMaxPacket>& v1, uint32_t* peer) {
  if (size < kHeader2Size) return Decode::kTooShort;
  uint32_t magic = 0;
  for (int i = 0; i < 4; ++i) magic |= static_cast<uint32_t>(p[i]) << (8 * i);
  if (magic != kMagic) return Decode::kBadMagic;
  if (p[4] != kVersion2) return Decode::kBadVersion;
  if (p[5] != kind) return Decode::kBadKind;
  if ((p[6] | (p[7] << 8)) != static_cast<int>(expected) || size != expected) return Decode::kBadLength;
  uint8_t mac[kMacSize];
  if (!Mac(key, p, size - kMacSize, mac) || CRYPTO_memcmp(mac, p + size - kMacSize, kMacSize) != 0) return Decode::kBadMac;
  const size_t v1_size = size - 4 - kMacSize;
  std::memcpy(v1.data(), p, kHeaderSize);
  v1[4] = kVersion;
  v1[6] = static_cast<uint8_t>(v1_size & 0xff);
  v1[7] = static_cast<uint8_t>(v1_size >> 8);
  std::memcpy(v1.data() + kHeaderSize, p + kHeader2Size, v1_size - kHeaderSize);
  *peer = 0;
  for (int i = 0; i < 4; ++i) *peer |= static_cast<uint32_t>(p[kHeaderSize + i]) << (8 * i);
  return Decode::kOk;
}

}  // namespace

StatusOr<std::string> ReadKeyFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0)
    return Status::InvalidArgument(path, errno == ELOOP ? "is a symbolic link: refused" : std::string(std::strerror(errno)));
  struct stat st {};
  std::string key;
  std::string problem;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    problem = "not a regular file";
  } else if ((st.st_mode & 077) != 0) {
    problem = "readable or writable by others: the key would not be secret (chmod 600 it)";
  } else {
    char buf[4096];
    for (;;) {
      const ssize_t n = ::read(fd, buf, sizeof buf);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      key.append(buf, static_cast<size_t>(n));
    }
    if (key.size() < kMinKeySize)
      problem = "shorter than " + std::to_string(kMinKeySize) + " bytes (e.g. head -c 32 /dev/urandom > KEY; chmod 600 KEY)";
  }
  ::close(fd);
  if (!problem.empty()) return Status::InvalidArgument(path, problem);
  return key;
}

size_t EncodeSigned(const CommandPacket& p, uint32_t peer, std::string_view key, std::array<uint8_t, kMaxPacket>& out) {
  std::array<uint8_t, kCommandSize> v1{};
  Encode(p, v1);
  return Sign(v1.data(), v1.size(), peer, key, out);
}

size_t EncodeSigned(const StatePacket& p, uint32_t peer, std::string_view key, std::array<uint8_t, kMaxPacket>& out) {
  std::array<uint8_t, kStateSize> v1{};
  Encode(p, v1);
  return Sign(v1.data(), v1.size(), peer, key, out);
}

size_t EncodeSigned(uint8_t kind, const HandshakePacket& p, std::string_view key, std::array<uint8_t, kMaxPacket>& out) {
  // A handshake is a header (sequence 0) and its peer: as a v1 image, a header alone.
  std::array<uint8_t, kHeaderSize> v1{};
  v1[0] = 'D', v1[1] = 'Y', v1[2] = 'R', v1[3] = 'C';
  v1[5] = kind;
  for (int i = 0; i < 4; ++i) v1[8 + i] = static_cast<uint8_t>(p.session >> (8 * i));
  return Sign(v1.data(), v1.size(), p.peer, key, out);
}

uint8_t SignedKind(const uint8_t* data, size_t size) {
  if (size < kHeader2Size || data[4] != kVersion2) return 0;
  return data[5];
}

Decode DecodeSignedCommand(const uint8_t* data, size_t size, std::string_view key, CommandPacket* out, uint32_t* peer) {
  std::array<uint8_t, kMaxPacket> v1{};
  if (Decode d = Verify(data, size, kKindCommand, kCommand2Size, key, v1, peer); d != Decode::kOk) return d;
  return DecodeCommand(v1.data(), kCommandSize, out);
}

Decode DecodeSignedState(const uint8_t* data, size_t size, std::string_view key, StatePacket* out, uint32_t* peer) {
  std::array<uint8_t, kMaxPacket> v1{};
  if (Decode d = Verify(data, size, kKindState, kState2Size, key, v1, peer); d != Decode::kOk) return d;
  return DecodeState(v1.data(), kStateSize, out);
}

Decode DecodeSignedHandshake(const uint8_t* data, size_t size, uint8_t kind, std::string_view key, HandshakePacket* out) {
  std::array<uint8_t, kMaxPacket> v1{};
  if (Decode d = Verify(data, size, kind, kHandshakeSize, key, v1, &out->peer); d != Decode::kOk) return d;
  out->session = 0;
  for (int i = 0; i < 4; ++i) out->session |= static_cast<uint32_t>(v1[8 + i]) << (8 * i);
  return Decode::kOk;
}

uint32_t ControllerSessions::Hello(uint32_t driver_session) {
  offered_driver_ = driver_session;
  offered_controller_ = NewSession();
  return offered_controller_;
}

ControllerSessions::Verdict ControllerSessions::Command(uint32_t driver_session, uint32_t controller_session,
                                                        uint32_t sequence) {
  const bool current = current_controller_ != 0 && driver_session == current_driver_ &&
                       controller_session == current_controller_;
  if (!current) {
    if (offered_controller_ == 0 || driver_session != offered_driver_ || controller_session != offered_controller_)
      return Verdict::kStaleSession;
    current_driver_ = offered_driver_;
    current_controller_ = offered_controller_;
    offered_driver_ = offered_controller_ = 0;
    has_applied_ = true;
    applied_ = sequence;
    return Verdict::kApplyNewSession;
  }
  if (has_applied_ && !Newer(sequence, applied_)) return Verdict::kOld;
  has_applied_ = true;
  applied_ = sequence;
  return Verdict::kApply;
}

}  // namespace dyad::cartesian::udp
