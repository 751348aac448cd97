#include "udp_protocol.hpp"

#include <cmath>
#include <cstring>
#include <initializer_list>
#include <random>

namespace dyad::cartesian::udp {

namespace {
// Explicit little-endian (de)serialisation: correct on any host byte order.
template <class U>
void PutU(uint8_t* p, U v) {
  for (size_t i = 0; i < sizeof(U); ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}
template <class U>
U GetU(const uint8_t* p) {
  U v = 0;
  for (size_t i = 0; i < sizeof(U); ++i) v |= static_cast<U>(p[i]) << (8 * i);
  return v;
}
void PutF64(uint8_t* p, double d) {
  uint64_t u;
  std::memcpy(&u, &d, 8);
  PutU<uint64_t>(p, u);
}
double GetF64(const uint8_t* p) {
  const uint64_t u = GetU<uint64_t>(p);
  double d;
  std::memcpy(&d, &u, 8);
  return d;
}
void PutHeader(uint8_t* p, uint8_t kind, uint16_t length, uint32_t session, uint32_t sequence) {
  PutU<uint32_t>(p, kMagic);
  p[4] = kVersion;
  p[5] = kind;
  PutU<uint16_t>(p + 6, length);
  PutU<uint32_t>(p + 8, session);
  PutU<uint32_t>(p + 12, sequence);
}
Decode CheckHeader(const uint8_t* p, size_t size, uint8_t kind, size_t expected) {
  if (size < kHeaderSize) return Decode::kTooShort;
  if (GetU<uint32_t>(p) != kMagic) return Decode::kBadMagic;
  if (p[4] != kVersion) return Decode::kBadVersion;
  if (p[5] != kind) return Decode::kBadKind;
  if (GetU<uint16_t>(p + 6) != expected || size != expected) return Decode::kBadLength;
  return Decode::kOk;
}
bool Finite(std::initializer_list<double> values) {
  for (double v : values)
    if (!std::isfinite(v)) return false;
  return true;
}
}  // namespace

uint32_t NewSession() {
  std::random_device rd;
  uint32_t s = 0;
  while (s == 0) s = static_cast<uint32_t>(rd());
  return s;
}

const char* ToString(Decode d) {
  switch (d) {
    case Decode::kOk: return "ok";
    case Decode::kTooShort: return "shorter than the header";
    case Decode::kBadMagic: return "bad magic";
    case Decode::kBadVersion: return "unsupported version";
    case Decode::kBadKind: return "unexpected kind";
    case Decode::kBadLength: return "bad length";
    case Decode::kNotFinite: return "a number is NaN or infinite";
    case Decode::kBadMac: return "bad MAC (another key, or modified)";
  }
  return "?";
}

void Encode(const CommandPacket& c, std::array<uint8_t, kCommandSize>& out) {
  uint8_t* p = out.data();
  PutHeader(p, kKindCommand, kCommandSize, c.session, c.sequence);
  PutU<uint64_t>(p + 16, static_cast<uint64_t>(c.stamp_ns));
  PutF64(p + 24, c.x);
  PutF64(p + 32, c.y);
  PutF64(p + 40, c.z);
  PutU<uint32_t>(p + 48, c.hold ? kFlagHold : 0);
  PutU<uint32_t>(p + 52, 0);
}

void Encode(const StatePacket& s, std::array<uint8_t, kStateSize>& out) {
  uint8_t* p = out.data();
  PutHeader(p, kKindState, kStateSize, s.session, s.sequence);
  PutU<uint32_t>(p + 16, s.ack);
  PutU<uint32_t>(p + 20, s.stopped ? kFlagStopped : 0);
  PutU<uint64_t>(p + 24, static_cast<uint64_t>(s.stamp_ns));
  PutF64(p + 32, s.x);
  PutF64(p + 40, s.y);
  PutF64(p + 48, s.z);
  PutF64(p + 56, s.vx);
  PutF64(p + 64, s.vy);
  PutF64(p + 72, s.vz);
}

Decode DecodeCommand(const uint8_t* p, size_t size, CommandPacket* c) {
  if (Decode d = CheckHeader(p, size, kKindCommand, kCommandSize); d != Decode::kOk) return d;
  c->session = GetU<uint32_t>(p + 8);
  c->sequence = GetU<uint32_t>(p + 12);
  c->stamp_ns = static_cast<int64_t>(GetU<uint64_t>(p + 16));
  c->x = GetF64(p + 24);
  c->y = GetF64(p + 32);
  c->z = GetF64(p + 40);
  c->hold = (GetU<uint32_t>(p + 48) & kFlagHold) != 0;
  return Finite({c->x, c->y, c->z}) ? Decode::kOk : Decode::kNotFinite;
}

Decode DecodeState(const uint8_t* p, size_t size, StatePacket* s) {
  if (Decode d = CheckHeader(p, size, kKindState, kStateSize); d != Decode::kOk) return d;
  s->session = GetU<uint32_t>(p + 8);
  s->sequence = GetU<uint32_t>(p + 12);
  s->ack = GetU<uint32_t>(p + 16);
  s->stopped = (GetU<uint32_t>(p + 20) & kFlagStopped) != 0;
  s->stamp_ns = static_cast<int64_t>(GetU<uint64_t>(p + 24));
  s->x = GetF64(p + 32);
  s->y = GetF64(p + 40);
  s->z = GetF64(p + 48);
  s->vx = GetF64(p + 56);
  s->vy = GetF64(p + 64);
  s->vz = GetF64(p + 72);
  return Finite({s->x, s->y, s->z, s->vx, s->vy, s->vz}) ? Decode::kOk : Decode::kNotFinite;
}

}  // namespace dyad::cartesian::udp
