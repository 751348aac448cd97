// Tests of EncodeYaml. The byte-for-byte tests fill fastddsgen's generated types with the values
// the YAML gives and serialize them with fastcdr 1.0.26 (the bytes Fast DDS puts on the wire);
// they need dyad_msgs (DYAD_CDR_WITH_FASTCDR). The rest checks hand-built bytes, round trips
// through Decode() and every error message.
#include "dyad/cdr_encoder.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "dyad/cdr_decoder.hpp"

#if DYAD_CDR_WITH_FASTCDR
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/rtps/common/SerializedPayload.h>

#include <dyad/msg/types.hpp>

#include "cdr_test_types.h"
#include "cdr_test_typesPubSubTypes.h"
#endif

#include "cdr_test_support.hpp"

namespace dyad::cdr {
namespace {

// Bytes as hex, 8 to a group: a failed comparison shows where the two differ.
std::string Hex(const std::vector<uint8_t>& bytes) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string s;
  for (size_t i = 0; i < bytes.size(); ++i) {
    if (i > 0) s += (i - 4) % 8 == 0 ? " | " : " ";  // groups aligned like the CDR body
    s += kHex[bytes[i] >> 4];
    s += kHex[bytes[i] & 15];
  }
  return s;
}

std::vector<uint8_t> EncodeOk(const Schema& schema, const std::string& type, const std::string& yaml,
                              const EncodeOptions& options = {}) {
  const StatusOr<std::vector<uint8_t>> bytes = EncodeYaml(schema, type, YAML::Load(yaml), options);
  EXPECT_TRUE(IsOk(bytes.status())) << yaml;
  return bytes.ok() ? *bytes : std::vector<uint8_t>();
}

std::string EncodeError(const Schema& schema, const std::string& type, const std::string& yaml,
                        const EncodeOptions& options = {}) {
  const StatusOr<std::vector<uint8_t>> bytes = EncodeYaml(schema, type, YAML::Load(yaml), options);
  EXPECT_FALSE(bytes.ok()) << yaml;
  if (bytes.ok()) return "";
  EXPECT_EQ(bytes.status().code(), dyad::Status::Code::kInvalidArgument) << bytes.status().ToString();
  return bytes.status().message();
}

// Decode()'s fields as one JSON object (ToJson), or the error.
std::string DecodeToJson(const Schema& schema, const std::string& type, const std::vector<uint8_t>& bytes) {
  std::vector<Field> fields;
  const dyad::Status s = Decode(schema, type, bytes.data(), bytes.size(), &fields);
  return s.ok() ? ToJson(fields) : s.ToString();
}

// ---------------------------------------------------------------------------------------------
// Hand-built bytes and round trips through Decode()

// kSmallIdl, SmallSample() and Writer are in cdr_test_support.hpp.

TEST(CdrEncode, WritesTheBytesOfAHandBuiltSample) {
  Schema schema = ParseOk(kSmallIdl);
  const std::vector<uint8_t> want = SmallSample(true);
  EXPECT_EQ(Hex(EncodeOk(schema, "m::S",
                         "{name: abc, v: 2.5, flag: true, mode: ON, ps: [{x: 1.5, y: -0.25}, "
                         "{x: 0, y: 1e300}], grid: [[1, -2], [3, -4]], big: 18446744073709551615}")),
            Hex(want));
  // The same in block style, members in another order, the enum by number, a type name with
  // leading colons and a runtime hash.
  EXPECT_EQ(Hex(EncodeOk(schema, "::m::S#0123456789abcdef",
                         "big: 0xFFFFFFFFFFFFFFFF\n"
                         "grid:\n  - [1, -2]\n  - [3, -4]\n"
                         "ps:\n  - x: 1.5\n    y: -0.25\n  - {y: 1e+300, x: 0.0}\n"
                         "mode: 1\nflag: True\nv: 2.5\nname: \"abc\"\n")),
            Hex(want));
}

TEST(CdrEncode, EmptyMappingIsTheZeroSample) {
  Schema schema = ParseOk(kSmallIdl);
  Writer w(true);
  w.Str("").Put(0.0).Put(uint8_t{0}).Put(uint32_t{0});  // "" is length 1: just the NUL
  w.Put(uint32_t{0});
  w.Put(int16_t{0}).Put(int16_t{0}).Put(int16_t{0}).Put(int16_t{0});
  w.Put(uint64_t{0});
  EXPECT_EQ(Hex(EncodeOk(schema, "m::S", "{}")), Hex(w.bytes()));
  // Members left out in nested structs and array elements are zero as well.
  Schema nested = ParseOk("struct In { octet a; double b; }; struct Out { In one; In two[2]; long c; };");
  Writer z(true);
  z.Put(uint8_t{7}).Put(0.0).Put(uint8_t{0}).Put(0.0).Put(uint8_t{0}).Put(-1.0).Put(int32_t{0});
  EXPECT_EQ(Hex(EncodeOk(nested, "Out", "{one: {a: 7}, two: [{}, {b: -1}]}")), Hex(z.bytes()));
}

TEST(CdrEncode, RoundTripsThroughDecode) {
  Schema schema = ParseOk(kSmallIdl);
  const auto bytes = EncodeOk(schema, "m::S",
                              "{name: 'it''s \"q\"', v: -0.0, flag: false, mode: OFF, ps: [{x: nan, y: -inf}], "
                              "grid: [[32767, -32768], [0x7fff, -0x8000]], big: 0}");
  EXPECT_EQ(DecodeToJson(schema, "m::S", bytes),
            R"({"name":"it's \"q\"","v":-0,"flag":false,"mode":"OFF","ps":[{"x":"nan","y":"-inf"}],)"
            R"("grid":[[32767,-32768],[32767,-32768]],"big":0})");
}

// What `dyad echo` prints (ToJson) reads back as YAML to the same bytes.
TEST(CdrEncode, DecodedJsonReadsBackToTheSameBytes) {
  Schema schema = ParseOk(R"(
    module t {
      enum Color { RED, GREEN, BLUE };
      struct Point { char tag; float x; double y; };
      struct S {
        Point corners[2];
        sequence<sequence<string> > names;
        Color colors[2];
        sequence<boolean> flags;
        float f;
        double d[3];
        string text;
      };
    };)");
  const std::string yaml =
      "{corners: [{tag: a, x: 0.1, y: 1e-300}, {tag: '', x: -3.4028235e38, y: 5e-324}], "
      "names: [[], ['', \"tab\\there\", 'quote\"'], [\"\\u0001\"]], colors: [BLUE, 1], "
      "flags: [true, false], f: -.inf, d: [.nan, 1.7976931348623157e308, -0.0], text: \"line\\nbreak\"}";
  const auto bytes = EncodeOk(schema, "t::S", yaml);
  const std::string json = DecodeToJson(schema, "t::S", bytes);
  EXPECT_EQ(json, R"({"corners":[{"tag":"a","x":0.1,"y":1e-300},{"tag":"","x":-3.4028235e+38,"y":5e-324}],)"
                  R"("names":[[],["","tab\there","quote\""],["\u0001"]],"colors":["BLUE","GREEN"],)"
                  R"("flags":[true,false],"f":"-inf","d":["nan",1.7976931348623157e+308,-0],"text":"line\nbreak"})");
  EXPECT_EQ(Hex(EncodeOk(schema, "t::S", json)), Hex(bytes));
}

TEST(CdrEncode, IntegersAtTheirExtremes) {
  Schema schema = ParseOk(R"(struct I {
    octet o; uint8 u8; int8 i8; short s; unsigned short us; long l; unsigned long ul;
    long long ll; unsigned long long ull; int16 i16; uint16 u16; int32 i32; uint32 u32;
    int64 i64; uint64 u64; };)");
  const std::string min_json =
      R"({"o":0,"u8":0,"i8":-128,"s":-32768,"us":0,"l":-2147483648,"ul":0,)"
      R"("ll":-9223372036854775808,"ull":0,"i16":-32768,"u16":0,"i32":-2147483648,"u32":0,)"
      R"("i64":-9223372036854775808,"u64":0})";
  const std::string max_json =
      R"({"o":255,"u8":255,"i8":127,"s":32767,"us":65535,"l":2147483647,"ul":4294967295,)"
      R"("ll":9223372036854775807,"ull":18446744073709551615,"i16":32767,"u16":65535,)"
      R"("i32":2147483647,"u32":4294967295,"i64":9223372036854775807,"u64":18446744073709551615})";
  EXPECT_EQ(DecodeToJson(schema, "I", EncodeOk(schema, "I", min_json)), min_json);
  EXPECT_EQ(DecodeToJson(schema, "I", EncodeOk(schema, "I", max_json)), max_json);
  // Hex, signs, leading zeros, "-0", quoted.
  EXPECT_EQ(DecodeToJson(schema, "I", EncodeOk(schema, "I",
                                               "{o: 0xff, u8: 0XFe, i8: -0x80, s: +0x7FFF, us: -0, "
                                               "l: '-0x80000000', ul: 007, ll: \"-1\", ull: 0x0, "
                                               "i16: -00, u16: 0xffff, i32: 0x7fffffff, u32: +4294967295, "
                                               "i64: -0x8000000000000000, u64: 0xffffffffffffffff}")),
            R"({"o":255,"u8":254,"i8":-128,"s":32767,"us":0,"l":-2147483648,"ul":7,"ll":-1,"ull":0,)"
            R"("i16":0,"u16":65535,"i32":2147483647,"u32":4294967295,"i64":-9223372036854775808,)"
            R"("u64":18446744073709551615})");
}

// The float and double a text gives, as bits.
struct RealCase {
  const char* text;
  uint32_t float_bits;
  uint64_t double_bits;
};

TEST(CdrEncode, RealsAreCorrectlyRoundedAndNonFiniteSpellingsAccepted) {
  Schema schema = ParseOk("struct R { float f; double d; };");
  const float fmax = std::numeric_limits<float>::max();
  auto fb = [](float v) { return std::bit_cast<uint32_t>(v); };
  auto db = [](double v) { return std::bit_cast<uint64_t>(v); };
  const float fnan = std::numeric_limits<float>::quiet_NaN();
  const double dnan = std::numeric_limits<double>::quiet_NaN();
  const float finf = std::numeric_limits<float>::infinity();
  const double dinf = std::numeric_limits<double>::infinity();
  const RealCase cases[] = {
      {"0.1", fb(0.1f), db(0.1)},
      {"-0", fb(-0.0f), db(-0.0)},
      {"-0.0", fb(-0.0f), db(-0.0)},
      {".5", fb(0.5f), db(0.5)},
      {"1.", fb(1.0f), db(1.0)},
      {"+2", fb(2.0f), db(2.0)},
      {"6.02214076e23", fb(6.02214076e23f), db(6.02214076e23)},
      {"16777217", fb(16777216.0f), db(16777217.0)},  // rounds to the nearest float
      {"0x10", fb(16.0f), db(16.0)},
      {"-0x10", fb(-16.0f), db(-16.0)},
      {"3.4028235e+38", fb(fmax), db(3.4028235e+38)},  // how Decode() prints FLT_MAX
      {"-3.4028234663852886e38", fb(-fmax), db(-3.4028234663852886e38)},
      {"1e-45", fb(std::numeric_limits<float>::denorm_min()), db(1e-45)},
      {"1e-50", fb(0.0f), db(1e-50)},       // too small for a float: 0, as in C++
      {"-1e-400", fb(-0.0f), db(-0.0)},     // and for a double
      {"1e-99999", fb(0.0f), db(0.0)},      // beyond long double
      {"5e-324", fb(0.0f), db(std::numeric_limits<double>::denorm_min())},
      {"nan", fb(fnan), db(dnan)},
      {".nan", fb(fnan), db(dnan)},
      {".NaN", fb(fnan), db(dnan)},
      {".NAN", fb(fnan), db(dnan)},
      {"inf", fb(finf), db(dinf)},
      {"+inf", fb(finf), db(dinf)},
      {"-inf", fb(-finf), db(-dinf)},
      {".inf", fb(finf), db(dinf)},
      {"+.Inf", fb(finf), db(dinf)},
      {"-.INF", fb(-finf), db(-dinf)},
      {"'-inf'", fb(-finf), db(-dinf)},  // quoted, as ToJson writes it
  };
  for (const RealCase& c : cases) {
    SCOPED_TRACE(c.text);
    const std::string t = c.text;
    const auto bytes = EncodeOk(schema, "R", "{f: " + t + ", d: " + t + "}");
    ASSERT_EQ(bytes.size(), 4u + 16u);
    uint32_t f = 0;
    uint64_t d = 0;
    for (int i = 3; i >= 0; --i) f = (f << 8) | bytes[4 + i];
    for (int i = 7; i >= 0; --i) d = (d << 8) | bytes[12 + i];
    EXPECT_EQ(f, c.float_bits);
    EXPECT_EQ(d, c.double_bits);
  }
}

TEST(CdrEncode, UnknownTypeIsNotFound) {
  Schema schema = ParseOk(kSmallIdl);
  const auto result = EncodeYaml(schema, "m::T", YAML::Load("{}"));
  EXPECT_EQ(result.status().code(), dyad::Status::Code::kNotFound);
  EXPECT_EQ(result.status().message(), "unknown type 'm::T' (the schema defines: m::P, m::S)");
  EXPECT_EQ(EncodeYaml(schema, "m::Mode", YAML::Load("{}")).status().code(), dyad::Status::Code::kNotFound);
  EXPECT_EQ(EncodeYaml(Schema(), "m::S", YAML::Load("{}")).status().message(),
            "unknown type 'm::S' (the schema defines no structs)");
}

TEST(CdrEncode, RequireAllNamesTheFirstMissingMember) {
  Schema schema = ParseOk(kSmallIdl);
  const EncodeOptions all{.require_all = true};
  EXPECT_EQ(EncodeError(schema, "m::S", "{}", all), "line 1, column 1: name: missing (every member is required)");
  EXPECT_EQ(EncodeError(schema, "m::S",
                        "name: a\nv: 1\nflag: true\nmode: ON\nps:\n  - {x: 1, y: 2}\n  - {x: 1}\n"
                        "grid: [[1, 2], [3, 4]]\nbig: 1\n",
                        all),
            "line 7, column 5: ps[1].y: missing (every member is required)");
  // Everything given: the same bytes as without the option.
  const std::string full = "{name: a, v: 1, flag: true, mode: ON, ps: [], grid: [[1, 2], [3, 4]], big: 1}";
  EXPECT_EQ(Hex(EncodeOk(schema, "m::S", full, all)), Hex(EncodeOk(schema, "m::S", full)));
}

TEST(CdrEncode, NodesBuiltInCodeHaveNoPosition) {
  Schema schema = ParseOk(kSmallIdl);
  YAML::Node fields;
  fields["name"] = "x";
  fields["ps"].push_back(YAML::Load("{x: 1}"));
  fields["ps"].push_back(YAML::Node());
  fields["ps"][1]["x"] = "wide";
  const auto result = EncodeYaml(schema, "m::S", fields);
  EXPECT_EQ(result.status().message(), "ps[1].x: expected a number (float), found 'wide'");
  // A node that is not there at all (a missing key of a const node).
  const YAML::Node parsed = YAML::Load("{a: 1}");
  EXPECT_EQ(EncodeYaml(schema, "m::S", parsed["b"]).status().message(),
            "sample: expected a mapping (the members of m::S), found nothing");
}

// ---------------------------------------------------------------------------------------------
// Errors

const char* kErrorIdl = R"(
module t {
  enum Color { RED, GREEN, BLUE };
  struct Point { char tag; float x; double y; };
  struct Base { long id; };
  struct S : Base {
    boolean b;
    octet o;
    long l;
    unsigned long long ull;
    int8 i8;
    float f;
    double d;
    char c;
    string name;
    string<3> short_name;
    Color color;
    Point point;
    sequence<Point> points;
    sequence<long, 2> two;
    double matrix[2][3];
  };
};
)";

using BadYaml = BadText;  // a YAML text and its error

class CdrEncodeError : public testing::TestWithParam<BadYaml> {};

TEST_P(CdrEncodeError, NamesThePositionAndPath) {
  static const Schema schema = ParseOk(kErrorIdl);
  EXPECT_EQ(EncodeError(schema, "t::S", GetParam().text), GetParam().error) << GetParam().text;
}

INSTANTIATE_TEST_SUITE_P(
    Golden, CdrEncodeError,
    testing::Values(
        // Structs
        BadYaml{"{bogus: 1}",
                "line 1, column 2: bogus: unknown member of t::S (members: id, b, o, l, ull, i8, f, d, c, "
                "name, short_name, color, point, points, two, matrix)"},
        BadYaml{"{point: {tag: a, z: 1}}",
                "line 1, column 18: point.z: unknown member of t::Point (members: tag, x, y)"},
        BadYaml{"{points: [{}, {x: 1, X: 2}]}",
                "line 1, column 22: points[1].X: unknown member of t::Point (members: tag, x, y)"},
        BadYaml{"{id: 1, b: true, id: 2}", "line 1, column 18: id: given twice"},
        BadYaml{"{[1]: 2}", "line 1, column 2: sample: expected member names as keys, found a sequence"},
        BadYaml{"[1, 2]", "line 1, column 1: sample: expected a mapping (the members of t::S), found a sequence"},
        BadYaml{"7", "line 1, column 1: sample: expected a mapping (the members of t::S), found '7'"},
        BadYaml{"{point: [1, 2]}",
                "line 1, column 9: point: expected a mapping (the members of t::Point), found a sequence"},
        BadYaml{"{point: }", "line 1, column 9: point: expected a mapping (the members of t::Point), found null"},
        BadYaml{"id: 1\npoint:\n  tag: p\n  x: nope\n",
                "line 4, column 6: point.x: expected a number (float), found 'nope'"},
        // Integers
        BadYaml{"{o: 300}", "line 1, column 5: o: 300 is out of range for octet (0..255)"},
        BadYaml{"{o: -1}", "line 1, column 5: o: -1 is out of range for octet (0..255)"},
        BadYaml{"{o: 0x100}", "line 1, column 5: o: 0x100 is out of range for octet (0..255)"},
        BadYaml{"{i8: -129}", "line 1, column 6: i8: -129 is out of range for int8 (-128..127)"},
        BadYaml{"{l: 2147483648}", "line 1, column 5: l: 2147483648 is out of range for long (-2147483648..2147483647)"},
        BadYaml{"{id: -2147483649}",
                "line 1, column 6: id: -2147483649 is out of range for long (-2147483648..2147483647)"},
        BadYaml{"{ull: 18446744073709551616}",
                "line 1, column 7: ull: 18446744073709551616 is out of range for unsigned long long "
                "(0..18446744073709551615)"},
        BadYaml{"{ull: -1}", "line 1, column 7: ull: -1 is out of range for unsigned long long (0..18446744073709551615)"},
        BadYaml{"{l: 1.5}", "line 1, column 5: l: expected an integer (long), found '1.5'"},
        BadYaml{"{l: 1e3}", "line 1, column 5: l: expected an integer (long), found '1e3'"},
        BadYaml{"{l: 2.0}", "line 1, column 5: l: expected an integer (long), found '2.0'"},
        BadYaml{"{l: 0o17}", "line 1, column 5: l: expected an integer (long), found '0o17'"},
        BadYaml{"{l: 0x}", "line 1, column 5: l: expected an integer (long), found '0x'"},
        BadYaml{"{l: +-1}", "line 1, column 5: l: expected an integer (long), found '+-1'"},
        BadYaml{"{l: ''}", "line 1, column 5: l: expected an integer (long), found ''"},
        BadYaml{"{l: }", "line 1, column 5: l: expected an integer (long), found null"},
        BadYaml{"{l: a-very-long-text-that-a-message-would-rather-not-repeat-whole}",
                "line 1, column 5: l: expected an integer (long), found 'a-very-long-text-that-a-message-would-ra...'"},
        BadYaml{"{l: [1]}", "line 1, column 5: l: expected an integer (long), found a sequence"},
        // Reals
        BadYaml{"{f: 1e39}", "line 1, column 5: f: 1e39 is out of range for float (largest finite: 3.4028235e+38)"},
        BadYaml{"{f: -3.5e38}", "line 1, column 5: f: -3.5e38 is out of range for float (largest finite: 3.4028235e+38)"},
        BadYaml{"{d: 1e400}",
                "line 1, column 5: d: 1e400 is out of range for double (largest finite: 1.7976931348623157e+308)"},
        BadYaml{"{d: 1e99999}",
                "line 1, column 5: d: 1e99999 is out of range for double (largest finite: 1.7976931348623157e+308)"},
        BadYaml{"{d: abc}", "line 1, column 5: d: expected a number (double), found 'abc'"},
        BadYaml{"{d: infinity}", "line 1, column 5: d: expected a number (double), found 'infinity'"},
        BadYaml{"{d: -nan}", "line 1, column 5: d: expected a number (double), found '-nan'"},
        BadYaml{"{d: 1_000}", "line 1, column 5: d: expected a number (double), found '1_000'"},
        BadYaml{"{d: 0x1p3}", "line 1, column 5: d: expected a number (double), found '0x1p3'"},
        BadYaml{"{d: {}}", "line 1, column 5: d: expected a number (double), found a mapping"},
        // Booleans, chars, strings
        BadYaml{"{b: yes}", "line 1, column 5: b: expected true or false (boolean), found 'yes'"},
        BadYaml{"{b: 1}", "line 1, column 5: b: expected true or false (boolean), found '1'"},
        BadYaml{"{b: tRUE}", "line 1, column 5: b: expected true or false (boolean), found 'tRUE'"},
        BadYaml{"{c: ab}", "line 1, column 5: c: expected one character (char), found 'ab'"},
        BadYaml{"{c: \xc3\xa9}", "line 1, column 5: c: expected one character (char), found '\xc3\xa9'"},
        BadYaml{"{name: }", "line 1, column 8: name: expected a string, found null (\"\" is the empty string)"},
        BadYaml{"{name: [a]}", "line 1, column 8: name: expected a string, found a sequence"},
        BadYaml{"{name: \"a\\0b\"}",
                "line 1, column 8: name: contains a NUL character (a CDR string ends at the first NUL)"},
        BadYaml{"{short_name: abcd}", "line 1, column 14: short_name: 4 bytes exceed the string's bound of 3"},
        // Enums
        BadYaml{"{color: PURPLE}",
                "line 1, column 9: color: expected an enumerator of t::Color (RED, GREEN, BLUE; or 0..2), found 'PURPLE'"},
        BadYaml{"{color: 3}",
                "line 1, column 9: color: expected an enumerator of t::Color (RED, GREEN, BLUE; or 0..2), found '3'"},
        BadYaml{"{color: t::RED}",
                "line 1, column 9: color: expected an enumerator of t::Color (RED, GREEN, BLUE; or 0..2), found 't::RED'"},
        BadYaml{"{color: red}",
                "line 1, column 9: color: expected an enumerator of t::Color (RED, GREEN, BLUE; or 0..2), found 'red'"},
        // Sequences and arrays
        BadYaml{"{two: [1, 2, 3]}", "line 1, column 7: two: 3 elements exceed the sequence's bound of 2"},
        BadYaml{"{two: 5}", "line 1, column 7: two: expected a sequence, found '5'"},
        BadYaml{"{points: {tag: a}}", "line 1, column 10: points: expected a sequence, found a mapping"},
        BadYaml{"{points: [{tag: a}, {x: oops}]}",
                "line 1, column 25: points[1].x: expected a number (float), found 'oops'"},
        BadYaml{"{matrix: [[1, 2, 3]]}", "line 1, column 10: matrix: expected 2 elements (a fixed array), 1 given"},
        BadYaml{"{matrix: [[1, 2, 3], [4, 5]]}",
                "line 1, column 22: matrix[1]: expected 3 elements (a fixed array), 2 given"},
        BadYaml{"{matrix: [[1, 2, 3], [4, 5, 6, 7]]}",
                "line 1, column 22: matrix[1]: expected 3 elements (a fixed array), 4 given"},
        BadYaml{"{matrix: [[1, 2, 3], [4, 5, x]]}",
                "line 1, column 29: matrix[1][2]: expected a number (double), found 'x'"},
        BadYaml{"{matrix: [1, 2]}", "line 1, column 11: matrix[0]: expected a sequence, found '1'"}));

// ---------------------------------------------------------------------------------------------
// Byte for byte against fastcdr, through fastddsgen's types

#if DYAD_CDR_WITH_FASTCDR

// Encodes `yaml` and expects fastcdr's bytes for `msg` (filled with the same values).
template <class T>
void ExpectSameBytes(const T& msg, const std::string& yaml) {
  Schema schema = ParseOk(MessageTraits<T>::kIdl);
  EXPECT_EQ(Hex(EncodeOk(schema, MessageTraits<T>::kName, yaml)), Hex(FastCdrBytes(msg)));
}

TEST(CdrEncodeFastcdr, Header) {
  ExpectSameBytes(MakeHeader("", 0, 0), "{}");
  ExpectSameBytes(MakeHeader("mind", std::numeric_limits<uint64_t>::max(), std::numeric_limits<int64_t>::min()),
                  "{source: mind, sequence_number: 18446744073709551615, stamp_ns: -9223372036854775808}");
}

TEST(CdrEncodeFastcdr, HumanInput) {
  ExpectSameBytes(HumanInputSample(),
                  "{header: {source: ab, sequence_number: 1, stamp_ns: -5}, x: -12.5, y: 0.1, engaged: true}");
}

TEST(CdrEncodeFastcdr, Intention) {
  msg::Intention m;
  m.header(MakeHeader("mind", 0xffffffffffffffffull, std::numeric_limits<int64_t>::max()));
  m.x(1.0 / 3);
  m.y(-2e-310);  // subnormal
  m.nelbo(std::numeric_limits<double>::max());
  m.reconstruction(std::numeric_limits<double>::infinity());
  m.regulation(-0.0);
  m.optimisation_s(std::numeric_limits<double>::quiet_NaN());
  m.iterations(4294967295u);
  m.deadline_missed(false);
  ExpectSameBytes(m,
                  "header: {source: mind, sequence_number: 0xffffffffffffffff, stamp_ns: 9223372036854775807}\n"
                  "x: 0.3333333333333333\ny: -2e-310\nnelbo: 1.7976931348623157e308\nreconstruction: .inf\n"
                  "regulation: -0.0\noptimisation_s: nan\niterations: 4294967295\ndeadline_missed: FALSE\n");
}

TEST(CdrEncodeFastcdr, IntentionLabelWithSequences) {
  msg::IntentionLabel m;
  m.header(MakeHeader("observer", 3, 17));  // 13 bytes: three of padding
  m.human({0.25, 0.75, 1e-9});
  m.congruence(0.5);
  ExpectSameBytes(m, "{header: {source: observer, sequence_number: 3, stamp_ns: 17}, "
                     "human: [0.25, 0.75, 1e-9], robot: [], congruence: 0.5}");
  m.human(std::vector<double>{});  // an empty sequence before a double
  m.robot({-1.5});
  ExpectSameBytes(m, "{header: {source: observer, sequence_number: 3, stamp_ns: 17}, robot: [-1.5], congruence: 0.5}");
}

TEST(CdrEncodeFastcdr, ComponentStats) {
  ExpectSameBytes(ComponentStatsSample(),
                  "{header: {source: runtime, sequence_number: 4, stamp_ns: 5}, component_name: mind, "
                  "process_name: dyad-run, steps: 123456789012345, step_mean_s: 0.001, step_p99_s: 0.002, "
                  "step_max_s: 0.01, jitter_mean_s: 1e-6, jitter_max_s: 2e-5, deadline_misses: 3}");
}

TEST(CdrEncodeFastcdr, PingPongWithOctets) {
  ExpectSameBytes(PingPongSample(),
                  "{header: {source: ping, sequence_number: 2, stamp_ns: 3}, id: 99, t0_ns: -1, payload: [0, 0xff, 7]}");
}

// Every dyad message type: the empty mapping gives the default-constructed sample, and a sample
// with every member set (numbers 7, booleans true, strings "s7", sequences [7, 7]) is what
// fastcdr writes again after reading it, and what Decode() reads.
TEST(CdrEncodeFastcdr, EveryDyadMessageType) {
  for (const TypeInfo* info : DyadTypes(14u)) {
    SCOPED_TRACE(info->name);
    Schema schema = ParseOk(info->idl);
    std::unique_ptr<eprosima::fastdds::dds::TopicDataType> type(info->make_type_support());
    void* data = type->createData();
    const std::vector<uint8_t> defaults = SerializeLikeFastDds(*type, data);
    EXPECT_EQ(Hex(EncodeOk(schema, info->name, "{}")), Hex(defaults));

    // The YAML of a sample with every member set, from the default sample's fields.
    std::vector<Field> fields;
    ASSERT_TRUE(IsOk(Decode(schema, info->name, defaults.data(), defaults.size(), &fields)));
    YAML::Node yaml(YAML::NodeType::Map);
    std::string want = "{";
    for (const Field& f : fields) {
      std::vector<std::string> names;
      std::stringstream path(f.path);
      for (std::string name; std::getline(path, name, '.');) names.push_back(name);
      YAML::Node node = yaml;
      for (const std::string& name : names) node.reset(node[name]);
      switch (f.kind) {
        case Field::Kind::kNumber: node = 7; break;
        case Field::Kind::kBool: node = true; break;
        case Field::Kind::kString: node = "s7"; break;
        case Field::Kind::kSequence: node.push_back(7); node.push_back(7); break;
      }
    }
    const StatusOr<std::vector<uint8_t>> bytes = EncodeYaml(schema, info->name, yaml);
    ASSERT_TRUE(IsOk(bytes.status()));
    eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<uint32_t>(bytes->size()));
    std::memcpy(payload.data, bytes->data(), bytes->size());
    payload.length = static_cast<uint32_t>(bytes->size());
    ASSERT_TRUE(type->deserialize(&payload, data));
    EXPECT_EQ(Hex(SerializeLikeFastDds(*type, data)), Hex(*bytes));
    std::vector<Field> decoded;
    ASSERT_TRUE(IsOk(Decode(schema, info->name, bytes->data(), bytes->size(), &decoded)));
    ASSERT_EQ(decoded.size(), fields.size() + 2 * std::count_if(fields.begin(), fields.end(), [](const Field& f) {
                                                  return f.kind == Field::Kind::kSequence;
                                                }));
    for (const Field& f : decoded) {
      EXPECT_EQ(f.value, f.kind == Field::Kind::kString ? "s7" : f.kind == Field::Kind::kBool ? "true"
                                                             : f.kind == Field::Kind::kSequence ? "2" : "7")
          << f.path;
    }
    type->deleteData(data);
  }
}

// EverythingSample() with its numbers at their extremes and its bounded sequence full, and the
// same as YAML.
dyad_cdr_test::Everything ExtremeEverything() {
  dyad_cdr_test::Everything m = EverythingSample();
  m.o(255);
  m.s(-32768);
  m.l(std::numeric_limits<int32_t>::min());
  m.ul(4294967295u);
  m.f(std::numeric_limits<float>::max());
  m.i16(32767);
  m.u16(0xffff);
  m.i32(std::numeric_limits<int32_t>::max());
  m.i64(std::numeric_limits<int64_t>::max());
  m.d2(std::numeric_limits<double>::lowest());
  m.bounded_points({Point('c', 5, 6), Point('d', 7, 8), Point('e', 9, 10), Point('f', 11, 12)});
  return m;
}

constexpr const char* kExtremeEverythingYaml = R"(
b1: true
d1: -1.25
o: 255
c: Q
s: -32768
us: 65535
l: -2147483648
ul: 4294967295
ll: -9223372036854775808
ull: 18446744073709551615
f: 3.4028235e+38
i8: -128
u8: 0xff
i16: 32767
u16: 0xFFFF
i32: 2147483647
u32: 7
i64: 9223372036854775807
u64: 0x8000000000000000
odd: xyz
d2: -1.7976931348623157e+308
bounded: "12345678"
color: BLUE
point: {tag: p, x: 1.5, y: -2.5}
points:
  - {tag: a, x: 1, y: 2}
  - {tag: b, x: 3, y: 4}
bounded_points: [{tag: c, x: 5, y: 6}, {tag: d, x: 7, y: 8}, {tag: e, x: 9, y: 10}, {tag: f, x: 11, y: 12}]
names: ["", one, three]
nested: [[1, 2, 3], [], [-4]]
flags: [true, false, true]
color_seq: [1, RED]
empty_doubles: []
b2: false
after_empty: 123
matrix: [[1, 2, 3], [4, 5, 6]]
corners: [{tag: x, x: -1, y: -2}, {tag: ""}]
colors: [0, GREEN]
v: [0.5, 1.5, 2.5]
ls: [-1, 0, 1]
tail: 9
)";

TEST(CdrEncodeFastcdr, EverythingTheSubsetSupports) {
  using namespace dyad_cdr_test;
  Schema schema = ParseOk(ReadFile(DYAD_CDR_TEST_IDL));
  EverythingPubSubType type;
  Everything m = ExtremeEverything();
  const auto bytes = EncodeOk(schema, "dyad_cdr_test::Everything", kExtremeEverythingYaml);
  EXPECT_EQ(Hex(bytes), Hex(SerializeLikeFastDds(type, &m)));
  // And Decode() reads back what fastcdr's own deserializer does.
  Everything back;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<uint32_t>(bytes.size()));
  std::memcpy(payload.data, bytes.data(), bytes.size());
  payload.length = static_cast<uint32_t>(bytes.size());
  ASSERT_TRUE(type.deserialize(&payload, &back));
  EXPECT_TRUE(back == m);
}

TEST(CdrEncodeFastcdr, EverythingWithNonFiniteAndTinyReals) {
  using namespace dyad_cdr_test;
  Schema schema = ParseOk(ReadFile(DYAD_CDR_TEST_IDL));
  EverythingPubSubType type;
  Everything m;
  m.d1(std::numeric_limits<double>::quiet_NaN());
  m.f(-std::numeric_limits<float>::infinity());
  m.d2(std::numeric_limits<double>::denorm_min());
  m.point(Point('\x7f', std::numeric_limits<float>::denorm_min(), -0.0));
  m.matrix({{{std::numeric_limits<double>::infinity(), -0.0, 0.1}, {1e-300, 1e300, -1}}});
  m.names({"x"});  // odd lengths before what follows
  m.odd("a");
  EXPECT_EQ(Hex(EncodeOk(schema, "dyad_cdr_test::Everything",
                         "{d1: .NaN, f: -.inf, d2: 5e-324, point: {tag: \"\\x7f\", x: 1.4e-45, y: -0.0}, "
                         "matrix: [[inf, -0.0, 0.1], [1e-300, 1e300, -1]], names: [x], odd: a}")),
            Hex(SerializeLikeFastDds(type, &m)));
}

TEST(CdrEncodeFastcdr, InheritedMembersByName) {
  using namespace dyad_cdr_test;
  Schema schema = ParseOk(ReadFile(DYAD_CDR_TEST_IDL));
  LabeledPubSubType type;
  Labeled m;
  m.tag('t');
  m.x(-0.5f);
  m.y(1e10);
  m.label("abcd");  // at its bound
  m.few({1, -2});   // at its bound
  m.id(65535);
  EXPECT_EQ(Hex(EncodeOk(schema, "dyad_cdr_test::Labeled", "{id: 65535, few: [1, -2], label: abcd, y: 1e10, x: -0.5, tag: t}")),
            Hex(SerializeLikeFastDds(type, &m)));
  EXPECT_EQ(EncodeError(schema, "dyad_cdr_test::Labeled", "{few: [1, 2, 3]}"),
            "line 1, column 7: few: 3 elements exceed the sequence's bound of 2");
  EXPECT_EQ(EncodeError(schema, "dyad_cdr_test::Labeled", "{label: abcde}"),
            "line 1, column 9: label: 5 bytes exceed the string's bound of 4");
  EXPECT_EQ(EncodeError(schema, "dyad_cdr_test::Labeled", "{point: {}}"),
            "line 1, column 2: point: unknown member of dyad_cdr_test::Labeled (members: tag, x, y, label, few, id)");
}

TEST(CdrEncodeFastcdr, EmptyMappingIsTheDefaultConstructedSample) {
  using namespace dyad_cdr_test;
  Schema schema = ParseOk(ReadFile(DYAD_CDR_TEST_IDL));
  {
    EverythingPubSubType type;
    Everything m;
    EXPECT_EQ(Hex(EncodeOk(schema, "dyad_cdr_test::Everything", "{}")), Hex(SerializeLikeFastDds(type, &m)));
  }
  {
    LabeledPubSubType type;
    Labeled m;
    EXPECT_EQ(Hex(EncodeOk(schema, "dyad_cdr_test::Labeled", "{}")), Hex(SerializeLikeFastDds(type, &m)));
  }
  {
    inner::PointPubSubType type;
    inner::Point m;
    EXPECT_EQ(Hex(EncodeOk(schema, "dyad_cdr_test::inner::Point", "{}")), Hex(SerializeLikeFastDds(type, &m)));
  }
}

#endif  // DYAD_CDR_WITH_FASTCDR

}  // namespace
}  // namespace dyad::cdr
