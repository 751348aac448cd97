// Test code only: the helpers that the dyad_cdr tests (cdr_decoder_test.cpp, cdr_encoder_test.cpp)
// share: IDL that must parse, golden error cases, a writer of hand-built CDR samples with the
// small schema and sample they build, and (with DYAD_CDR_WITH_FASTCDR) Fast DDS's serialization,
// the dyad message types and the samples of fastddsgen's types that both check.
#pragma once

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "dyad/cdr_decoder.hpp"
#include <dyad/msg/types_support.hpp>  // PubSubType of the message types it serializes

#if DYAD_CDR_WITH_FASTCDR
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/rtps/common/SerializedPayload.h>

#include <dyad/msg/types.hpp>

#include "cdr_test_types.h"
#endif

namespace dyad::cdr {

inline ::testing::AssertionResult IsOk(const dyad::Status& s) {
  if (s.ok()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << s.ToString();
}

inline Schema ParseOk(const std::string& idl) {
  dyad::StatusOr<Schema> s = Schema::Parse(idl);
  EXPECT_TRUE(IsOk(s.status()));
  return s.ok() ? *s : Schema();
}

inline std::string ReadFile(const char* path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A case of a golden error test: the text given (IDL, YAML) and the error it must give.
struct BadText {
  const char* text;
  const char* error;
};
// Names each case by its expected error in the test output and in CTest (stable across runs,
// unlike gtest's default byte dump of the two pointers).
inline void PrintTo(const BadText& bad, std::ostream* os) { *os << bad.error; }

// ---------------------------------------------------------------------------------------------
// Hand-built samples

// Appends values to a CDR body with natural alignment, in either byte order.
class Writer {
 public:
  explicit Writer(bool little) : little_(little) {
    bytes_ = {0x00, static_cast<uint8_t>(little ? 0x01 : 0x00), 0x00, 0x00};
  }
  template <class T>
  Writer& Put(T v) {
    while ((bytes_.size() - 4) % sizeof(T) != 0) bytes_.push_back(0);
    uint8_t raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));
    const bool host_little = std::endian::native == std::endian::little;
    for (size_t i = 0; i < sizeof(T); ++i) {
      bytes_.push_back(raw[little_ == host_little ? i : sizeof(T) - 1 - i]);
    }
    return *this;
  }
  Writer& Str(const std::string& s) {
    Put(static_cast<uint32_t>(s.size() + 1));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back(0);
    return *this;
  }
  std::vector<uint8_t> bytes() const { return bytes_; }

 private:
  bool little_;
  std::vector<uint8_t> bytes_;
};

inline constexpr const char* kSmallIdl = R"(
// A small schema for hand-built samples.
module m {
  enum Mode { OFF, ON };
  struct P { float x; double y; };
  struct S {
    string name;
    double v;
    boolean flag;
    Mode mode;
    sequence<P> ps;
    short grid[2][2];
    uint64 big;
  };
};
)";

// An m::S of kSmallIdl: {name: abc, v: 2.5, flag: true, mode: ON, ps: [{x: 1.5, y: -0.25},
// {x: 0, y: 1e300}], grid: [[1, -2], [3, -4]], big: 18446744073709551615}.
inline std::vector<uint8_t> SmallSample(bool little) {
  Writer w(little);
  w.Str("abc").Put(2.5).Put(uint8_t{1}).Put(uint32_t{1});
  w.Put(uint32_t{2}).Put(1.5f).Put(-0.25).Put(0.0f).Put(1e300);
  w.Put(int16_t{1}).Put(int16_t{-2}).Put(int16_t{3}).Put(int16_t{-4});
  w.Put(std::numeric_limits<uint64_t>::max());
  return w.bytes();
}

#if DYAD_CDR_WITH_FASTCDR

// ---------------------------------------------------------------------------------------------
// fastcdr and fastddsgen's types

// The bytes Fast DDS puts on the wire: the type support's serialize() into a zeroed payload
// (little endian here).
inline std::vector<uint8_t> SerializeLikeFastDds(eprosima::fastdds::dds::TopicDataType& type, void* data) {
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(data)());
  EXPECT_TRUE(type.serialize(data, &payload));
  return std::vector<uint8_t>(payload.data, payload.data + payload.length);
}

// The same for a message type with MessageTraits.
template <class T>
std::vector<uint8_t> FastCdrBytes(T msg) {
  typename MessageTraits<T>::PubSubType type;
  return SerializeLikeFastDds(type, &msg);
}

// Every dyad message type (msg::AllTypes()), expecting at least `at_least` of them.
inline std::vector<const TypeInfo*> DyadTypes(size_t at_least) {
  std::vector<const TypeInfo*> types = msg::AllTypes();
  EXPECT_GE(types.size(), at_least);
  return types;
}

inline msg::Header MakeHeader(const std::string& source, uint64_t seq, int64_t stamp) {
  msg::Header h;
  h.source(source);
  h.sequence_number(seq);
  h.stamp_ns(stamp);
  return h;
}

inline msg::HumanInput HumanInputSample() {
  msg::HumanInput m;
  m.header(MakeHeader("ab", 1, -5));  // 7-byte string: one byte of padding before the u64
  m.x(-12.5);
  m.y(0.1);
  m.engaged(true);
  return m;
}

inline msg::ComponentStats ComponentStatsSample() {
  msg::ComponentStats m;
  m.header(MakeHeader("runtime", 4, 5));
  m.component_name("mind");    // 5 bytes with NUL, then another string
  m.process_name("dyad-run");  // 9 bytes with NUL, then a u64
  m.steps(123456789012345ull);
  m.step_mean_s(0.001);
  m.step_p99_s(0.002);
  m.step_max_s(0.01);
  m.jitter_mean_s(1e-6);
  m.jitter_max_s(2e-5);
  m.deadline_misses(3);
  return m;
}

inline msg::PingPong PingPongSample() {
  msg::PingPong m;
  m.header(MakeHeader("ping", 2, 3));
  m.id(99);
  m.t0_ns(-1);
  m.payload({0, 255, 7});
  return m;
}

inline dyad_cdr_test::inner::Point Point(char tag, float x, double y) {
  dyad_cdr_test::inner::Point p;
  p.tag(tag);
  p.x(x);
  p.y(y);
  return p;
}

// Every member of Everything set, most to a telling value (odd lengths, padding, nesting).
inline dyad_cdr_test::Everything EverythingSample() {
  using namespace dyad_cdr_test;
  Everything m;
  m.b1(true);
  m.d1(-1.25);
  m.o(200);
  m.c('Q');
  m.s(-300);
  m.us(65535);
  m.l(-2000000000);
  m.ul(4000000000u);
  m.ll(std::numeric_limits<int64_t>::min());
  m.ull(std::numeric_limits<uint64_t>::max());
  m.f(0.1f);
  m.i8(-128);
  m.u8(255);
  m.i16(-32768);
  m.u16(1);
  m.i32(std::numeric_limits<int32_t>::min());
  m.u32(7);
  m.i64(-1);
  m.u64(1ull << 63);
  m.odd("xyz");
  m.d2(6.02214076e23);
  m.bounded("12345678");  // at its bound
  m.color(BLUE);
  m.point(Point('p', 1.5f, -2.5));
  m.points({Point('a', 1, 2), Point('b', 3, 4)});
  m.bounded_points({Point('c', 5, 6)});
  m.names({"", "one", "three"});
  m.nested({{1, 2, 3}, {}, {-4}});
  m.flags({true, false, true});
  m.color_seq({GREEN, RED});
  m.b2(false);
  m.after_empty(123);
  m.matrix({{{1, 2, 3}, {4, 5, 6}}});
  m.corners({Point('x', -1, -2), Point('\0', 0, 0)});
  m.colors({RED, GREEN});
  m.v({0.5, 1.5, 2.5});
  m.ls({-1, 0, 1});
  m.tail(9);
  return m;
}

#endif  // DYAD_CDR_WITH_FASTCDR

}  // namespace dyad::cdr
