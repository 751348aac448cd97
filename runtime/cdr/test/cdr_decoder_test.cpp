// Tests of dyad_cdr. The round trips serialize samples with fastddsgen's generated types and
// fastcdr 1.0.26 (the bytes Fast DDS puts on the wire) and check that the decoder reads every
// field back; they need dyad_msgs (DYAD_CDR_WITH_FASTCDR). The rest uses hand-built bytes.
#include "dyad/cdr_decoder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#if DYAD_CDR_WITH_FASTCDR
#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>

#include <dyad/msg/types.hpp>

#include "cdr_test_types.h"
#include "cdr_test_typesPubSubTypes.h"
#endif

#include "cdr_test_support.hpp"

namespace dyad::cdr {
namespace {

// ---------------------------------------------------------------------------------------------
// Expectations

// What one decoded field must be. Reals are compared by value, bit for bit, after reading the
// text back (so the test does not depend on the exact digits, only on exact round-tripping).
struct Want {
  std::string path;
  std::string text;
  Field::Kind kind;
  std::optional<double> real;  // double, or float widened
  bool is_float = false;
};

Want S(std::string path, std::string text) { return {std::move(path), std::move(text), Field::Kind::kString, {}}; }
Want B(std::string path, bool v) { return {std::move(path), v ? "true" : "false", Field::Kind::kBool, {}}; }
template <class T>
Want N(std::string path, T v) {
  static_assert(std::is_integral_v<T>);
  return {std::move(path), std::to_string(v), Field::Kind::kNumber, {}};
}
Want D(std::string path, double v) { return {std::move(path), "", Field::Kind::kNumber, v}; }
Want F(std::string path, float v) { return {std::move(path), "", Field::Kind::kNumber, v, true}; }
Want Seq(std::string path, size_t count) {
  return {std::move(path), std::to_string(count), Field::Kind::kSequence, {}};
}

std::string Dump(const std::vector<Field>& fields) {
  std::ostringstream s;
  for (const Field& f : fields) s << "  " << f.path << " = " << f.value << "\n";
  return s.str();
}

void ExpectFields(const std::vector<Field>& got, const std::vector<Want>& want) {
  ASSERT_EQ(got.size(), want.size()) << Dump(got);
  for (size_t i = 0; i < got.size(); ++i) {
    SCOPED_TRACE(want[i].path);
    EXPECT_EQ(got[i].path, want[i].path);
    EXPECT_EQ(static_cast<int>(got[i].kind), static_cast<int>(want[i].kind));
    if (!want[i].real) {
      EXPECT_EQ(got[i].value, want[i].text);
    } else if (want[i].is_float) {
      const float w = static_cast<float>(*want[i].real);
      const float g = std::strtof(got[i].value.c_str(), nullptr);
      EXPECT_EQ(std::memcmp(&w, &g, sizeof w), 0) << got[i].value << " vs " << w;
    } else {
      const double w = *want[i].real;
      const double g = std::strtod(got[i].value.c_str(), nullptr);
      EXPECT_EQ(std::memcmp(&w, &g, sizeof w), 0) << got[i].value << " vs " << w;
    }
  }
}

std::string ParseError(const std::string& idl) { return Schema::Parse(idl).status().message(); }

std::vector<Field> DecodeOk(const Schema& schema, const std::string& type,
                            const std::vector<uint8_t>& bytes) {
  std::vector<Field> fields;
  std::string error;
  EXPECT_TRUE(IsOk(Decode(schema, type, bytes.data(), bytes.size(), &fields)));
  return fields;
}

// Every shorter prefix of a valid sample is an error, never a crash or a read past the end.
void ExpectEveryTruncationFails(const Schema& schema, const std::string& type,
                                const std::vector<uint8_t>& bytes) {
  std::vector<Field> fields;
  std::vector<std::string> row;
  for (size_t n = 0; n < bytes.size(); ++n) {
    // A fresh copy of exactly n bytes, so ASan catches any read past the end.
    std::vector<uint8_t> prefix(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
    const dyad::Status decoded = Decode(schema, type, prefix.data(), n, &fields);
    EXPECT_EQ(decoded.code(), dyad::Status::Code::kDataLoss) << "length " << n << ": " << decoded.ToString();
    EXPECT_FALSE(decoded.message().empty()) << "length " << n;
    const dyad::Status row_decoded = DecodeRow(schema, type, prefix.data(), n, &row);
    EXPECT_EQ(row_decoded.code(), dyad::Status::Code::kDataLoss) << "length " << n << ": " << row_decoded.ToString();
  }
}

// Random byte changes: decoding may fail or succeed, but must stay in bounds.
void ExpectGarblingIsSafe(const Schema& schema, const std::string& type,
                          const std::vector<uint8_t>& bytes) {
  std::mt19937 rng(7);
  std::vector<Field> fields;
  std::vector<std::string> row;
  std::string error;
  for (int round = 0; round < 500; ++round) {
    std::vector<uint8_t> garbled = bytes;
    const int changes = 1 + static_cast<int>(rng() % 4);
    for (int k = 0; k < changes; ++k) {
      garbled[4 + rng() % (garbled.size() - 4)] = static_cast<uint8_t>(rng());
    }
    (void)Decode(schema, type, garbled.data(), garbled.size(), &fields);
    (void)DecodeRow(schema, type, garbled.data(), garbled.size(), &row);
  }
}

// The row holds, per column, the value of the field with the same path, or for a sequence the
// JSON array of its elements.
void ExpectRowMatchesFields(const Schema& schema, const std::string& type,
                            const std::vector<uint8_t>& bytes) {
  std::vector<Field> fields = DecodeOk(schema, type, bytes);
  std::vector<std::string> columns = Columns(schema, type);
  std::vector<std::string> row;
  std::string error;
  ASSERT_TRUE(IsOk(DecodeRow(schema, type, bytes.data(), bytes.size(), &row)));
  ASSERT_EQ(row.size(), columns.size());
  for (size_t c = 0; c < columns.size(); ++c) {
    bool found = false;
    for (const Field& f : fields) {
      if (f.path != columns[c]) continue;
      found = true;
      if (f.kind == Field::Kind::kSequence) {
        EXPECT_EQ(row[c].front(), '[') << columns[c];
        EXPECT_EQ(row[c].back(), ']') << columns[c];
      } else {
        EXPECT_EQ(row[c], f.value) << columns[c];
      }
      break;
    }
    EXPECT_TRUE(found) << "column " << columns[c] << " has no field";
  }
}

// ---------------------------------------------------------------------------------------------
// Hand-built samples

// Writer, kSmallIdl and SmallSample() are in cdr_test_support.hpp.

std::vector<Want> SmallWant() {
  return {S("name", "abc"), D("v", 2.5), B("flag", true), S("mode", "ON"), Seq("ps", 2),
          F("ps[0].x", 1.5f), D("ps[0].y", -0.25), F("ps[1].x", 0.0f), D("ps[1].y", 1e300),
          N("grid[0][0]", 1), N("grid[0][1]", -2), N("grid[1][0]", 3), N("grid[1][1]", -4),
          N("big", std::numeric_limits<uint64_t>::max())};
}

TEST(CdrDecode, ReadsHandBuiltLittleEndianSample) {
  Schema schema = ParseOk(kSmallIdl);
  ExpectFields(DecodeOk(schema, "m::S", SmallSample(true)), SmallWant());
}

TEST(CdrDecode, ReadsHandBuiltBigEndianSample) {
  Schema schema = ParseOk(kSmallIdl);
  ExpectFields(DecodeOk(schema, "m::S", SmallSample(false)), SmallWant());
}

TEST(CdrDecode, FailsOnEveryTruncationOfAHandBuiltSample) {
  Schema schema = ParseOk(kSmallIdl);
  ExpectEveryTruncationFails(schema, "m::S", SmallSample(true));
  ExpectGarblingIsSafe(schema, "m::S", SmallSample(true));
}

TEST(CdrDecode, AcceptsLeadingColonsAndRuntimeHashSuffix) {
  Schema schema = ParseOk(kSmallIdl);
  EXPECT_TRUE(schema.HasType("::m::S"));
  EXPECT_TRUE(schema.HasType("m::S#0123456789abcdef"));
  EXPECT_FALSE(schema.HasType("S"));
  EXPECT_FALSE(schema.HasType("m::Mode"));  // only structs are decodable
  ExpectFields(DecodeOk(schema, "m::S#0123456789abcdef", SmallSample(true)), SmallWant());
}

TEST(CdrDecode, UnknownTypeErrorListsTheKnownStructs) {
  Schema schema = ParseOk(kSmallIdl);
  std::vector<Field> fields;
  std::string error;
  const auto bytes = SmallSample(true);
  EXPECT_EQ(Decode(schema, "m::T", bytes.data(), bytes.size(), &fields).code(), dyad::Status::Code::kNotFound);
  error = Decode(schema, "m::T", bytes.data(), bytes.size(), &fields).message();
  EXPECT_EQ(error, "unknown type 'm::T' (the schema defines: m::P, m::S)");
  error = Decode(Schema(), "m::S", bytes.data(), bytes.size(), &fields).message();
  EXPECT_EQ(error, "unknown type 'm::S' (the schema defines no structs)");
  EXPECT_TRUE(Columns(schema, "m::T").empty());
}

TEST(CdrDecode, RejectsEncapsulationsOtherThanPlainCdr) {
  Schema schema = ParseOk(kSmallIdl);
  auto bytes = SmallSample(true);
  std::vector<Field> fields;
  std::string error;
  bytes[1] = 0x03;  // PL_CDR_LE
  EXPECT_EQ(Decode(schema, "m::S", bytes.data(), bytes.size(), &fields).code(), dyad::Status::Code::kUnimplemented);
  error = Decode(schema, "m::S", bytes.data(), bytes.size(), &fields).message();
  EXPECT_EQ(error, "encapsulation 0x0003 is not supported (only plain CDR: 0x0000 big endian, "
                   "0x0001 little endian)");
  error = Decode(schema, "m::S", bytes.data(), 3, &fields).message();
  EXPECT_EQ(error, "sample of 3 bytes is shorter than the 4-byte encapsulation header");
  error = Decode(schema, "m::S", nullptr, 0, &fields).message();
}

TEST(CdrDecode, ErrorNamesOffsetAndField) {
  Schema schema = ParseOk(kSmallIdl);
  auto bytes = SmallSample(true);
  std::vector<Field> fields;
  std::string error;
  EXPECT_EQ(Decode(schema, "m::S", bytes.data(), 4 + 8 + 5, &fields).code(), dyad::Status::Code::kDataLoss);
  error = Decode(schema, "m::S", bytes.data(), 4 + 8 + 5, &fields).message();
  EXPECT_EQ(error, "offset 8 (v): truncated: double needs 8 bytes, 5 left");
  error = Decode(schema, "m::S", bytes.data(), 4 + 52, &fields).message();
  EXPECT_EQ(error, "offset 48 (ps[1].y): truncated: double needs 8 bytes, 4 left");
  // Too few bytes left for the elements at all: caught before decoding them.
  error = Decode(schema, "m::S", bytes.data(), 4 + 50, &fields).message();
  EXPECT_EQ(error, "offset 28 (ps): sequence of 2 elements needs at least 24 bytes, 22 left");
}

TEST(CdrDecode, RejectsBooleanBytesOtherThanZeroOrOne) {
  Schema schema = ParseOk(kSmallIdl);
  auto bytes = SmallSample(true);
  bytes[4 + 16] = 2;  // flag
  std::vector<Field> fields;
  std::string error;
  error = Decode(schema, "m::S", bytes.data(), bytes.size(), &fields).message();
  EXPECT_EQ(error, "offset 16 (flag): boolean byte is 2 (must be 0 or 1)");
}

TEST(CdrDecode, HugeSequenceCountIsAnErrorNotAnAllocation) {
  Schema schema = ParseOk("struct Q { sequence<octet> data; };");
  const auto bytes = Writer(true).Put(uint32_t{0xfffffff0}).Put(uint8_t{1}).bytes();
  std::vector<Field> fields;
  std::string error;
  error = Decode(schema, "Q", bytes.data(), bytes.size(), &fields).message();
  EXPECT_EQ(error, "offset 4 (data): sequence of 4294967280 elements needs at least 4294967280 "
                   "bytes, 1 left");
}

TEST(CdrDecode, StringsToleratesMissingNulAndZeroLength) {
  Schema schema = ParseOk("struct Q { string a; string b; char c; char d; };");
  Writer w(true);
  w.Put(uint32_t{0});                                                      // a: length 0
  w.Put(uint32_t{2}).Put(uint8_t{'h'}).Put(uint8_t{'i'});                  // b: no NUL
  w.Put(uint8_t{'z'}).Put(uint8_t{0});
  ExpectFields(DecodeOk(schema, "Q", w.bytes()), {S("a", ""), S("b", "hi"), S("c", "z"), S("d", "")});
}

TEST(CdrDecode, EnumValueWithoutEnumeratorIsPrintedAsNumber) {
  Schema schema = ParseOk("enum E { A, B }; struct Q { E e; E f; };");
  const auto bytes = Writer(true).Put(uint32_t{1}).Put(uint32_t{7}).bytes();
  ExpectFields(DecodeOk(schema, "Q", bytes), {S("e", "B"), N("f", 7)});
}

TEST(CdrDecode, IgnoresTrailingPadding) {
  Schema schema = ParseOk("struct Q { octet a; };");
  auto bytes = Writer(true).Put(uint8_t{9}).bytes();
  bytes.insert(bytes.end(), {0, 0, 0});
  ExpectFields(DecodeOk(schema, "Q", bytes), {N("a", 9)});
}

TEST(CdrDecode, FormatsNumbersSoTheyReadBackExactly) {
  Schema schema = ParseOk(
      "struct Q { double a, b, c, d, e, f; float g, h; long long i; int8 j; octet k; };");
  Writer w(true);
  w.Put(0.1).Put(-0.0).Put(5e-324).Put(std::numeric_limits<double>::infinity());
  w.Put(-std::numeric_limits<double>::infinity()).Put(std::numeric_limits<double>::quiet_NaN());
  w.Put(0.1f).Put(3.4028235e38f).Put(std::numeric_limits<int64_t>::min());
  w.Put(int8_t{-128}).Put(uint8_t{255});
  std::vector<Field> fields = DecodeOk(schema, "Q", w.bytes());
  ASSERT_EQ(fields.size(), 11u);
  EXPECT_EQ(fields[0].value, "0.1");  // shortest exact form, not 0.10000000000000001
  EXPECT_EQ(fields[1].value, "-0");
  EXPECT_EQ(fields[2].value, "5e-324");
  EXPECT_EQ(fields[3].value, "inf");
  EXPECT_EQ(fields[4].value, "-inf");
  EXPECT_EQ(fields[5].value, "nan");
  EXPECT_EQ(fields[6].value, "0.1");
  EXPECT_EQ(std::strtof(fields[7].value.c_str(), nullptr), 3.4028235e38f);
  EXPECT_EQ(fields[8].value, "-9223372036854775808");
  EXPECT_EQ(fields[9].value, "-128");
  EXPECT_EQ(fields[10].value, "255");
}

// ---------------------------------------------------------------------------------------------
// JSON and CSV

TEST(CdrJson, NestsObjectsAndArraysAsThePathsSay) {
  Schema schema = ParseOk(kSmallIdl);
  EXPECT_EQ(ToJson(DecodeOk(schema, "m::S", SmallSample(true))),
            R"({"name":"abc","v":2.5,"flag":true,"mode":"ON","ps":[{"x":1.5,"y":-0.25},)"
            R"({"x":0,"y":1e+300}],"grid":[[1,-2],[3,-4]],"big":18446744073709551615})");
}

TEST(CdrJson, WritesEmptySequencesNestedSequencesAndEscapes) {
  Schema schema = ParseOk(
      "struct Q { sequence<double> e; sequence<sequence<long> > n; string s; double x; };");
  Writer w(true);
  w.Put(uint32_t{0});
  w.Put(uint32_t{3}).Put(uint32_t{0}).Put(uint32_t{1}).Put(int32_t{-7}).Put(uint32_t{0});
  w.Str("a\"b\\c\nd\x01");
  w.Put(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(ToJson(DecodeOk(schema, "Q", w.bytes())),
            R"({"e":[],"n":[[],[-7],[]],"s":"a\"b\\c\nd\u0001","x":"nan"})");
}

TEST(CdrJson, EmptyFieldListIsAnEmptyObject) { EXPECT_EQ(ToJson({}), "{}"); }

TEST(CdrCsv, ColumnsUnrollArraysAndGiveSequencesOneJsonColumn) {
  Schema schema = ParseOk(kSmallIdl);
  EXPECT_EQ(Columns(schema, "m::S"),
            (std::vector<std::string>{"name", "v", "flag", "mode", "ps", "grid[0][0]",
                                      "grid[0][1]", "grid[1][0]", "grid[1][1]", "big"}));
  std::vector<std::string> row = {"stale", "cells", "are", "replaced", "", "", "", "", "", "",
                                  "and extra ones dropped"};
  std::string error;
  const auto bytes = SmallSample(true);
  ASSERT_TRUE(IsOk(DecodeRow(schema, "m::S", bytes.data(), bytes.size(), &row)));
  EXPECT_EQ(row, (std::vector<std::string>{"abc", "2.5", "true", "ON",
                                           R"([{"x":1.5,"y":-0.25},{"x":0,"y":1e+300}])", "1",
                                           "-2", "3", "-4", "18446744073709551615"}));
}

TEST(CdrCsv, SequenceInsideArrayGetsOneColumnPerElement) {
  Schema schema = ParseOk("struct In { sequence<string> tags; }; struct Q { In a[2]; octet z; };");
  EXPECT_EQ(Columns(schema, "Q"), (std::vector<std::string>{"a[0].tags", "a[1].tags", "z"}));
  Writer w(true);
  w.Put(uint32_t{2}).Str("x").Str("y\"").Put(uint32_t{0}).Put(uint8_t{5});
  std::vector<std::string> row;
  std::string error;
  const auto bytes = w.bytes();
  ASSERT_TRUE(IsOk(DecodeRow(schema, "Q", bytes.data(), bytes.size(), &row)));
  EXPECT_EQ(row, (std::vector<std::string>{R"(["x","y\""])", "[]", "5"}));
  ExpectRowMatchesFields(schema, "Q", bytes);
}

// ---------------------------------------------------------------------------------------------
// IDL parsing

TEST(CdrSchema, DefaultSchemaKnowsNoTypes) { EXPECT_FALSE(Schema().HasType("dyad::msg::Header")); }

TEST(CdrSchema, AcceptsTheDocumentedSubset) {
  Schema schema = ParseOk(R"(
#ifndef GUARD_IDL
#define GUARD_IDL
#include "header.idl"
#pragma once
/* block
   comment */ module outer {
  const unsigned long kN = 3;
  typedef sequence<octet, 16> Blob;
  module inner {
    @final struct Base { @key long id; };
  };
  @topic
  @extensibility(APPENDABLE)
  struct Derived : inner::Base {
    double x, y[kN];       // several declarators
    ::outer::inner::Base b;
    Blob blob;
    string<0x10> name;
    @unit("m") @range(min=0, max=1) float f;
  };
  module inner {
    struct UsesOuter { Derived d; };   // found in the enclosing module
  };
};
// Repeated identically, as when a file is inlined twice.
module outer { module inner { struct Base { long id; }; }; };
#endif
)");
  EXPECT_TRUE(schema.HasType("outer::Derived"));
  EXPECT_TRUE(schema.HasType("outer::inner::UsesOuter"));
  EXPECT_EQ(Columns(schema, "outer::Derived"),
            (std::vector<std::string>{"id", "x", "y[0]", "y[1]", "y[2]", "b.id", "blob", "name", "f"}));
}

TEST(CdrSchema, UnsupportedKeywordsAreFineAsMemberNames) {
  Schema schema = ParseOk("struct A { long component; double local, home; };");
  EXPECT_EQ(Columns(schema, "A"), (std::vector<std::string>{"component", "local", "home"}));
}

TEST(CdrSchema, RejectsAbsurdNestingAndExpansion) {
  std::string deep = "struct A { ";
  for (int i = 0; i < 100; ++i) deep += "sequence<";
  deep += "long";
  for (int i = 0; i < 100; ++i) deep += "> ";
  deep += "x; };";
  EXPECT_EQ(ParseError(deep), "line 1: nesting deeper than 64 levels");

  // (Built by appending: GCC 12 warns falsely about "literal" + std::to_string(i).)
  auto name = [](int i) {
    std::string n = "S";
    n.append(std::to_string(i));
    return n;
  };
  std::string chain = "struct S0 { double a; };\n";
  for (int i = 1; i < 100; ++i) chain.append("struct " + name(i) + " { " + name(i - 1) + " a; };\n");
  EXPECT_EQ(ParseError(chain), "line 64: types nested deeper than 64 levels");

  // Each struct holds two of the one before: the expansion doubles per line.
  std::string wide = "struct S0 { double a; };\n";
  for (int i = 1; i < 30; ++i) {
    wide.append("struct " + name(i) + " { " + name(i - 1) + " a; " + name(i - 1) + " b; };\n");
  }
  EXPECT_EQ(ParseError(wide), "line 20: struct 'S19' is too large to decode (more than 1048576 "
                              "steps once nested structs are expanded)");
}

TEST(CdrSchema, SurvivesRandomlyMangledText) {
  std::mt19937 rng(11);
  const std::string original = kSmallIdl;
  const std::string alphabet = "{}<>[];:,@#/*\"\n abc019";
  for (int round = 0; round < 3000; ++round) {
    std::string idl = original;
    const int changes = 1 + static_cast<int>(rng() % 5);
    for (int k = 0; k < changes; ++k) idl[rng() % idl.size()] = alphabet[rng() % alphabet.size()];
    dyad::StatusOr<Schema> parsed = Schema::Parse(idl);
    if (!parsed.ok()) {
      EXPECT_EQ(parsed.status().message().rfind("line ", 0), 0u) << parsed.status().ToString();
      continue;
    }
    const Schema& schema = *parsed;
    // Whatever it now describes, decoding the original sample with it stays in bounds.
    const auto bytes = SmallSample(true);
    std::vector<Field> fields;
    std::vector<std::string> row;
    for (const char* type : {"m::S", "m::P"}) {
      (void)Decode(schema, type, bytes.data(), bytes.size(), &fields);
      (void)DecodeRow(schema, type, bytes.data(), bytes.size(), &row);
    }
  }
}

using BadIdl = BadText;  // an IDL text and its error

class CdrSchemaError : public testing::TestWithParam<BadIdl> {};

TEST_P(CdrSchemaError, NamesTheLine) {
  EXPECT_EQ(ParseError(GetParam().text), GetParam().error);
  // Valid IDL this reader does not support is Unimplemented; anything else InvalidArgument.
  const bool unsupported = std::string(GetParam().error).find("not supported") != std::string::npos ||
                           std::string(GetParam().error).find("too large to decode") != std::string::npos;
  EXPECT_EQ(Schema::Parse(GetParam().text).status().code(),
            unsupported ? dyad::Status::Code::kUnimplemented : dyad::Status::Code::kInvalidArgument);
}

INSTANTIATE_TEST_SUITE_P(
    Golden, CdrSchemaError,
    testing::Values(
        BadIdl{"module m {\n  struct A { long a; };\n  union U switch (long) { case 1: long x; };\n};",
               "line 3: 'union' is not supported"},
        BadIdl{"struct A {\n  map<long, long> m;\n};", "line 2: 'map' is not supported"},
        BadIdl{"struct A {\n  wstring w;\n};", "line 2: 'wstring' is not supported"},
        BadIdl{"struct A {\n  long double w;\n};", "line 2: 'long double' is not supported"},
        BadIdl{"struct A {\n  Missing m;\n};", "line 2: unknown type 'Missing'"},
        BadIdl{"struct A {\n  long a\n};", "line 3: expected ';' after a member, found '}'"},
        BadIdl{"struct A {\n  @optional long a;\n};", "line 2: annotation @optional is not supported"},
        BadIdl{"@mutable\nstruct A { long a; };", "line 1: annotation @mutable is not supported"},
        BadIdl{"@extensibility(MUTABLE)\nstruct A { long a; };",
               "line 1: @extensibility(MUTABLE) is not supported (only FINAL and APPENDABLE)"},
        BadIdl{"struct A { long a; };\n/* open\n\n", "line 2: unterminated /* comment"},
        BadIdl{"#define N 3\nstruct A { long a[N]; };",
               "line 1: preprocessor directive '#define' is not supported (only #include, "
               "#pragma and include guards, which are ignored)"},
        BadIdl{"struct A;\n", "line 1: forward declaration of struct 'A' is not supported"},
        BadIdl{"struct Node {\n  sequence<Node> children;\n};", "line 2: unknown type 'Node'"},
        BadIdl{"struct A {\n  long a;\n  double a;\n};", "line 3: struct 'A' has two members named 'a'"},
        BadIdl{"struct A { long a; };\nstruct A { double a; };",
               "line 2: 'A' is already defined (line 1) differently"},
        BadIdl{"struct A {\n};", "line 1: struct 'A' has no members (not supported)"},
        BadIdl{"struct A {\n  long a[0];\n};", "line 2: an array size must be between 1 and 4294967295, not 0"},
        BadIdl{"enum E {\n  A = 1 };", "line 2: enumerator values are not supported"},
        BadIdl{"module m {\n  struct A { long a; };\n", "line 3: expected '}' closing module 'm', found end of text"},
        BadIdl{"interface I {};", "line 1: 'interface' is not supported"}));

// ---------------------------------------------------------------------------------------------
// Round trips through fastddsgen's types and fastcdr

#if DYAD_CDR_WITH_FASTCDR

// The same serialization (fastcdr, DDS_CDR, encapsulation first) in big-endian byte order.
template <class T>
std::vector<uint8_t> SerializeBigEndian(const T& msg) {
  eprosima::fastcdr::FastBuffer buffer;
  eprosima::fastcdr::Cdr ser(buffer, eprosima::fastcdr::Cdr::BIG_ENDIANNESS,
                             eprosima::fastcdr::Cdr::DDS_CDR);
  ser.serialize_encapsulation();
  msg.serialize(ser);
  return std::vector<uint8_t>(buffer.getBuffer(), buffer.getBuffer() + ser.getSerializedDataLength());
}

// Decodes both byte orders, checks every field, every truncation, garbling and the CSV row.
template <class T>
void CheckRoundTrip(const T& msg, const std::string& idl, const std::string& type,
                    const std::vector<Want>& want) {
  Schema schema = ParseOk(idl);
  ASSERT_TRUE(schema.HasType(type));
  const auto little = FastCdrBytes(msg);
  const auto big = SerializeBigEndian(msg);
  ASSERT_EQ(little[1], 0x01);
  ASSERT_EQ(big[1], 0x00);
  ASSERT_EQ(little.size(), big.size());
  {
    SCOPED_TRACE("little endian");
    ExpectFields(DecodeOk(schema, type, little), want);
  }
  {
    SCOPED_TRACE("big endian");
    ExpectFields(DecodeOk(schema, type, big), want);
  }
  ExpectEveryTruncationFails(schema, type, little);
  ExpectGarblingIsSafe(schema, type, little);
  ExpectRowMatchesFields(schema, type, little);
}

template <class T>
void CheckDyadMessage(const T& msg, const std::vector<Want>& want) {
  CheckRoundTrip(msg, MessageTraits<T>::kIdl, MessageTraits<T>::kName, want);
}

std::vector<Want> HeaderWant(const std::string& source, uint64_t seq, int64_t stamp) {
  return {S("header.source", source), N("header.sequence_number", seq), N("header.stamp_ns", stamp)};
}

template <class... V>
std::vector<Want> Cat(std::vector<Want> a, const V&... rest) {
  (a.insert(a.end(), rest.begin(), rest.end()), ...);
  return a;
}

TEST(CdrRoundTrip, EveryDyadMessageTypeParses) {
  for (const TypeInfo* info : DyadTypes(9u)) {
    SCOPED_TRACE(info->name);
    Schema schema = ParseOk(info->idl);
    EXPECT_TRUE(schema.HasType(info->name));
    EXPECT_TRUE(schema.HasType("dyad::msg::Header"));
    EXPECT_EQ(Columns(schema, info->name).at(0), info->name == "dyad::msg::Header" ? "source" : "header.source");
  }
}

TEST(CdrRoundTrip, Header) {
  CheckRoundTrip(MakeHeader("", 0, 0), MessageTraits<msg::Header>::kIdl, "dyad::msg::Header",
                 {S("source", ""), N("sequence_number", 0), N("stamp_ns", 0)});
}

TEST(CdrRoundTrip, HumanInput) {
  CheckDyadMessage(HumanInputSample(),
                   Cat(HeaderWant("ab", 1, -5), std::vector<Want>{D("x", -12.5), D("y", 0.1), B("engaged", true)}));
}

TEST(CdrRoundTrip, Intention) {
  msg::Intention m;
  m.header(MakeHeader("mind", std::numeric_limits<uint64_t>::max(), std::numeric_limits<int64_t>::min()));
  m.x(1.0 / 3);
  m.y(-2e-310);  // subnormal
  m.nelbo(12345.678);
  m.reconstruction(std::numeric_limits<double>::infinity());
  m.regulation(-0.0);
  m.optimisation_s(0.004);
  m.iterations(4000000000u);
  m.deadline_missed(false);
  CheckDyadMessage(m, Cat(HeaderWant("mind", std::numeric_limits<uint64_t>::max(),
                                     std::numeric_limits<int64_t>::min()),
                          std::vector<Want>{D("x", 1.0 / 3), D("y", -2e-310), D("nelbo", 12345.678),
                                            Want{"reconstruction", "inf", Field::Kind::kNumber, {}}, D("regulation", -0.0),
                                            D("optimisation_s", 0.004), N("iterations", 4000000000u),
                                            B("deadline_missed", false)}));
}

TEST(CdrRoundTrip, IntentionLabelWithSequences) {
  msg::IntentionLabel m;
  m.header(MakeHeader("observer", 3, 17));  // 13 bytes: three of padding
  m.human({0.25, 0.75, 1e-9});
  m.robot(std::vector<double>{});
  m.congruence(0.5);
  CheckDyadMessage(m, Cat(HeaderWant("observer", 3, 17),
                          std::vector<Want>{Seq("human", 3), D("human[0]", 0.25), D("human[1]", 0.75),
                                            D("human[2]", 1e-9), Seq("robot", 0), D("congruence", 0.5)}));
}

TEST(CdrRoundTrip, IntentionLabelWithEmptySequenceBeforeADouble) {
  msg::IntentionLabel m;
  m.header(MakeHeader("o", 1, 2));
  m.human(std::vector<double>{});
  m.robot({-1.5});
  m.congruence(0.125);
  CheckDyadMessage(m, Cat(HeaderWant("o", 1, 2),
                          std::vector<Want>{Seq("human", 0), Seq("robot", 1), D("robot[0]", -1.5),
                                            D("congruence", 0.125)}));
}

TEST(CdrRoundTrip, CartesianCommand) {
  msg::CartesianCommand m;
  m.header(MakeHeader("mixer", 10, 1700000000000000000));
  m.x(50);
  m.y(-50);
  m.z(0);
  m.hold(true);
  CheckDyadMessage(m, Cat(HeaderWant("mixer", 10, 1700000000000000000),
                          std::vector<Want>{D("x", 50), D("y", -50), D("z", 0), B("hold", true)}));
}

TEST(CdrRoundTrip, CartesianState) {
  msg::CartesianState m;
  m.header(MakeHeader("robot-driver", 11, 12));
  m.x(1.1);
  m.y(2.2);
  m.z(3.3);
  m.vx(-0.5);
  m.vy(0.25);
  m.vz(1e10);
  m.stopped(true);
  CheckDyadMessage(m, Cat(HeaderWant("robot-driver", 11, 12),
                          std::vector<Want>{D("x", 1.1), D("y", 2.2), D("z", 3.3), D("vx", -0.5),
                                            D("vy", 0.25), D("vz", 1e10), B("stopped", true)}));
}

TEST(CdrRoundTrip, ComponentStats) {
  CheckDyadMessage(ComponentStatsSample(),
                   Cat(HeaderWant("runtime", 4, 5),
                       std::vector<Want>{S("component_name", "mind"), S("process_name", "dyad-run"),
                                         N("steps", 123456789012345ull), D("step_mean_s", 0.001),
                                         D("step_p99_s", 0.002), D("step_max_s", 0.01),
                                         D("jitter_mean_s", 1e-6), D("jitter_max_s", 2e-5),
                                         N("deadline_misses", 3)}));
}

TEST(CdrRoundTrip, Counter) {
  msg::Counter m;
  m.header(MakeHeader("counter", 1, 1));
  m.value(-42);
  CheckDyadMessage(m, Cat(HeaderWant("counter", 1, 1), std::vector<Want>{N("value", -42)}));
}

TEST(CdrRoundTrip, PingPongWithPayload) {
  CheckDyadMessage(PingPongSample(),
                   Cat(HeaderWant("ping", 2, 3),
                       std::vector<Want>{N("id", 99), N("t0_ns", -1), Seq("payload", 3),
                                         N("payload[0]", 0), N("payload[1]", 255), N("payload[2]", 7)}));
}

TEST(CdrRoundTrip, PingPongWithEmptyPayload) {
  msg::PingPong m;
  m.header(MakeHeader("pong", 2, 3));
  m.id(1);
  m.t0_ns(2);
  CheckDyadMessage(m, Cat(HeaderWant("pong", 2, 3),
                          std::vector<Want>{N("id", 1), N("t0_ns", 2), Seq("payload", 0)}));
}

}  // namespace
}  // namespace dyad::cdr

// fastddsgen's types for test/cdr_test_types.idl have no MessageTraits; give them one here so
// CheckRoundTrip can find their type support.
template <>
struct dyad::MessageTraits<dyad_cdr_test::Everything> {
  using PubSubType = dyad_cdr_test::EverythingPubSubType;
};

namespace dyad::cdr {
namespace {

TEST(CdrRoundTrip, EverythingTheSubsetSupports) {
  CheckRoundTrip(
      EverythingSample(), ReadFile(DYAD_CDR_TEST_IDL), "dyad_cdr_test::Everything",
      {B("b1", true), D("d1", -1.25), N("o", 200), S("c", "Q"), N("s", -300), N("us", 65535),
       N("l", -2000000000), N("ul", 4000000000u), N("ll", std::numeric_limits<int64_t>::min()),
       N("ull", std::numeric_limits<uint64_t>::max()), F("f", 0.1f), N("i8", -128), N("u8", 255),
       N("i16", -32768), N("u16", 1), N("i32", std::numeric_limits<int32_t>::min()), N("u32", 7),
       N("i64", -1), N("u64", 1ull << 63), S("odd", "xyz"), D("d2", 6.02214076e23),
       S("bounded", "12345678"), S("color", "BLUE"),
       S("point.tag", "p"), F("point.x", 1.5f), D("point.y", -2.5),
       Seq("points", 2), S("points[0].tag", "a"), F("points[0].x", 1), D("points[0].y", 2),
       S("points[1].tag", "b"), F("points[1].x", 3), D("points[1].y", 4),
       Seq("bounded_points", 1), S("bounded_points[0].tag", "c"), F("bounded_points[0].x", 5),
       D("bounded_points[0].y", 6),
       Seq("names", 3), S("names[0]", ""), S("names[1]", "one"), S("names[2]", "three"),
       Seq("nested", 3), Seq("nested[0]", 3), N("nested[0][0]", 1), N("nested[0][1]", 2),
       N("nested[0][2]", 3), Seq("nested[1]", 0), Seq("nested[2]", 1), N("nested[2][0]", -4),
       Seq("flags", 3), B("flags[0]", true), B("flags[1]", false), B("flags[2]", true),
       Seq("color_seq", 2), S("color_seq[0]", "GREEN"), S("color_seq[1]", "RED"),
       Seq("empty_doubles", 0), B("b2", false), N("after_empty", 123),
       D("matrix[0][0]", 1), D("matrix[0][1]", 2), D("matrix[0][2]", 3),
       D("matrix[1][0]", 4), D("matrix[1][1]", 5), D("matrix[1][2]", 6),
       S("corners[0].tag", "x"), F("corners[0].x", -1), D("corners[0].y", -2),
       S("corners[1].tag", ""), F("corners[1].x", 0), D("corners[1].y", 0),
       S("colors[0]", "RED"), S("colors[1]", "GREEN"),
       D("v[0]", 0.5), D("v[1]", 1.5), D("v[2]", 2.5),
       Seq("ls", 3), N("ls[0]", -1), N("ls[1]", 0), N("ls[2]", 1), N("tail", 9)});
}

TEST(CdrRoundTrip, EverythingWithEmptySequencesAndStrings) {
  using namespace dyad_cdr_test;
  Everything m;  // defaults: zeros, empty strings and sequences
  m.u8(1);
  const std::string idl = ReadFile(DYAD_CDR_TEST_IDL);
  Schema schema = ParseOk(idl);
  const auto little = FastCdrBytes(m);
  const auto big = SerializeBigEndian(m);
  std::vector<Field> a = DecodeOk(schema, "dyad_cdr_test::Everything", little);
  std::vector<Field> b = DecodeOk(schema, "dyad_cdr_test::Everything", big);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].path, b[i].path);
    EXPECT_EQ(a[i].value, b[i].value);
  }
  EXPECT_TRUE(ToJson(a).starts_with(R"({"b1":false,"d1":0,"o":0,"c":"","s":0,)")) << ToJson(a);
  ExpectEveryTruncationFails(schema, "dyad_cdr_test::Everything", little);
}

#endif  // DYAD_CDR_WITH_FASTCDR

}  // namespace
}  // namespace dyad::cdr
