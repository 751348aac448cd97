// dyad/cdr_decoder.hpp — turns serialized DDS samples into named field values, driven by the IDL
// text of their type: no compiled (fastddsgen) types needed. `dyad echo` prints samples with it;
// `dyad bag export --csv` turns recorded samples into CSV columns with it. The reverse, samples
// from YAML values, is dyad/cdr_encoder.hpp.
//
// INPUT
//   A sample exactly as Fast DDS 2.9 puts it on the wire and an MCAP recording stores it: the
//   4-byte encapsulation header (0x00 0x00 = plain CDR big endian, 0x00 0x01 = plain CDR little
//   endian; the two option bytes are ignored), then the plain (XCDR1) CDR body as fastcdr 1.0.26
//   (Cdr::DDS_CDR) writes it:
//     - every primitive aligned to its own size (1, 2, 4 or 8), counted from the first byte after
//       the encapsulation header; no padding at struct boundaries;
//     - boolean: one byte, 0 or 1 (anything else is an error, as in fastcdr);
//     - string: uint32 length including the NUL, then the bytes and the NUL (length 0 is read as
//       the empty string, a missing NUL is tolerated, as fastcdr does);
//     - sequence: uint32 element count, then the elements; fixed array: the elements;
//     - enum: uint32.
//   Bytes after the last member are ignored (writers may pad). Bounds of string<N> and
//   sequence<T, N> are not enforced when decoding (fastcdr 1.0.26 does not enforce them either).
//
// SUPPORTED IDL (the text dyad_generate_type_traits() stores: a file with its includes inlined)
//   - `module` (nested), `struct` (single inheritance `struct B : A` puts A's members first),
//     `enum`, `typedef`, `const` of an integer type with an integer literal value (usable as a
//     bound or array size); `//` and `/* */` comments.
//   - Member types: boolean, octet, char, short, unsigned short, long, unsigned long, long long,
//     unsigned long long, float, double, int8, uint8, int16, uint16, int32, uint32, int64, uint64,
//     string, string<N>, sequence<T>, sequence<T, N> of any supported T (nested too), fixed
//     arrays `T name[N][M]...`, structs and enums defined earlier, named relative to the current
//     module or qualified (`inner::Point`, `::dyad::msg::Header`). Several declarators per member
//     line (`double x, y;`) are fine.
//   - Preprocessor lines #include, #pragma and include guards (#ifndef X, #define X, #endif) are
//     ignored. A definition repeated identically (a file inlined twice) is accepted once.
//   - Annotations that do not change the plain-CDR layout are accepted and ignored: @key, @topic,
//     @nested, @final, @appendable, @extensibility(FINAL|APPENDABLE), @unit, @min, @max, @range,
//     @default, @verbatim.
//   Unsupported, reported as a parse error naming the line: union, map, bitset, bitmask, wchar,
//   wstring, long double, fixed, any, interface, valuetype, exception, forward declarations (so no
//   recursive types), @optional, @mutable, @value and any other annotation, other preprocessor
//   directives, const expressions. Limits (also parse errors): types nested more than 64 levels
//   deep; a struct that expands to more than 2^20 decoding steps (structs inside structs are
//   expanded; arrays and sequences are loops, whatever their length).
//
// OUTPUT
//   Decode() gives one Field per leaf value, in declaration order (depth first). Paths join member
//   names with '.' and element indices with [i]: "header.stamp_ns", "human[3]", "corners[1].x",
//   "matrix[1][2]". Every sequence also gives a Field of kind kSequence holding its element count
//   before its elements (so empty sequences are visible). Values are text:
//     - integers in decimal; float and double in the shortest form that reads back to the same
//       value (std::to_chars), "nan", "inf", "-inf" for non-finite values;
//     - boolean "true" / "false"; char the character itself ("" for '\0');
//     - string the bytes as they are (not checked to be UTF-8);
//     - enum the enumerator's name, or its number when the number names no enumerator.
//   ToJson() renders fields as one compact, nested JSON object:
//     {"header":{"source":"mind","sequence_number":3,"stamp_ns":17},"human":[0.25,0.75],...}
//   Non-finite numbers become the JSON strings "nan", "inf", "-inf".
//
//   For CSV, Columns() names one column per leaf outside sequences, named like the field paths
//   (fixed arrays are unrolled: "matrix[0][0]", ...). A sequence cannot have fixed columns: it gets
//   one column, named after it ("human"), holding its elements as a compact JSON array
//   ("[0.25,0.75]", "[{\"x\":1,\"y\":2}]"). DecodeRow() fills a row in that column order with the
//   same value texts as Decode(); it does no CSV quoting (that is the CSV writer's job).
//
// ERRORS (a dyad::Status; its code says what kind of problem it is)
//   Schema::Parse: "line N: message" (N counts from 1): Unimplemented for valid IDL this reader
//   does not support ("line 7: 'union' is not supported"), InvalidArgument for anything else.
//   Decode / DecodeRow: NotFound for a type the schema does not define; Unimplemented for an
//   encapsulation other than plain CDR; DataLoss for a payload that is truncated or garbled:
//   "offset N (path): message" where N is the byte offset in the payload after the encapsulation
//   header, e.g. "offset 24 (header.stamp_ns): truncated: long long needs 8 bytes, 3 left".
//   Truncated or garbled payloads never read out of bounds; a garbled sequence count (or an
//   array) larger than the remaining bytes could hold is an error, caught before any element is
//   decoded.
//   On failure the output holds what was decoded before the error.
//
// PERFORMANCE / THREADS
//   Parse compiles every struct once into a flat list of ops; decoding walks the ops with no
//   per-field allocation besides the output strings (DecodeRow reuses the row's strings), about
//   1 us for a 14-value sample, most of it formatting doubles. A Schema is immutable and cheap to
//   copy (shared); all functions are safe to call concurrently.
//
// EXAMPLE
//   dyad::StatusOr<dyad::cdr::Schema> schema = dyad::cdr::Schema::Parse(idl_text);
//   if (!schema.ok()) { std::cerr << "schema: " << schema.status().message() << "\n"; return; }
//   std::vector<dyad::cdr::Field> fields;
//   if (dyad::Status s = dyad::cdr::Decode(*schema, "dyad::msg::HumanInput", data, size, &fields); !s.ok()) {
//     std::cerr << s.message() << "\n"; return;
//   }
//   std::cout << dyad::cdr::ToJson(fields) << "\n";
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <dyad/status.hpp>

namespace dyad::cdr {

namespace internal {
struct SchemaImpl;
}  // namespace internal

// Parsed IDL: the structs, enums and typedefs it defines, each struct compiled for decoding.
class Schema {
 public:
  // An empty schema: knows no types.
  Schema();

  // Parses `idl_text`: the schema, or the first problem as "line N: message" (see ERRORS).
  static StatusOr<Schema> Parse(const std::string& idl_text);

  // True if `qualified_name` names a struct of this schema ("dyad::msg::HumanInput"; a leading
  // "::" is allowed). Only structs can be decoded.
  bool HasType(const std::string& qualified_name) const;

 private:
  friend const internal::SchemaImpl* ImplOf(const Schema& schema);
  explicit Schema(std::shared_ptr<const internal::SchemaImpl> impl);
  std::shared_ptr<const internal::SchemaImpl> impl_;  // never null
};

// One decoded value (see OUTPUT above).
struct Field {
  enum class Kind : uint8_t {
    kString,    // string, char or enum: JSON quotes it
    kNumber,    // integer or floating point (possibly "nan", "inf", "-inf")
    kBool,      // "true" or "false"
    kSequence,  // a sequence itself: value is its element count; its elements follow
  };
  std::string path;   // "header.stamp_ns", "human[3]"
  std::string value;  // the value as text
  Kind kind = Kind::kString;
};

// Decodes one serialized sample (`data`, `size` bytes, starting with the 4-byte encapsulation
// header) of the struct `root_type` (fully qualified; a "#<hash>" suffix, as in the runtime's DDS
// type names, is ignored). Replaces *out with its fields. On an unknown type or a truncated or
// garbled payload returns the error (see ERRORS) and *out holds what was decoded before it.
Status Decode(const Schema& schema, const std::string& root_type, const uint8_t* data, size_t size,
              std::vector<Field>* out);

// Renders fields produced by Decode() as one compact nested JSON object (see OUTPUT above).
std::string ToJson(const std::vector<Field>& fields);

// The CSV column names of struct `root_type`: one per leaf outside sequences, one per sequence
// (its elements as a JSON array). Empty if the schema has no such struct.
std::vector<std::string> Columns(const Schema& schema, const std::string& root_type);

// Decodes one sample like Decode(), into *row: one value per column of Columns(), same order.
// Reuses the row's strings (no allocation once they have grown, and none on success: an OK
// Status is free). Returns the error (see ERRORS) on an unknown type or a bad payload.
Status DecodeRow(const Schema& schema, const std::string& root_type, const uint8_t* data,
                 size_t size, std::vector<std::string>* row);

}  // namespace dyad::cdr
