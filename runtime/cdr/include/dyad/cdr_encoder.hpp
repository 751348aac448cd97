// dyad/cdr_encoder.hpp — the reverse of dyad/cdr_decoder.hpp: serializes one DDS sample from
// member values given as YAML, driven by the IDL text of its type (a cdr::Schema); no compiled
// (fastddsgen) types needed. `dyad pub TOPIC '{x: 1, y: 2}'` publishes with it.
//
// OUTPUT
//   The 4-byte encapsulation header 0x00 0x01 0x00 0x00 (plain CDR, little endian), then the
//   body byte for byte as fastcdr 1.0.26 (Cdr::DDS_CDR) serializes the same values through
//   fastddsgen's types, i.e. what Fast DDS 2.9 puts on the wire on a little-endian host: the
//   wire format of dyad/cdr_decoder.hpp (INPUT), with padding bytes zero, strings written as
//   uint32 length including the NUL then the bytes and the NUL (the empty string too: 1, 0), and
//   nothing after the last member. Decode() reads it back to the same values.
//
// INPUT
//   `fields` is a YAML mapping of the root struct's member names to values; what a value may be
//   is decided by the member's IDL type (quoting does not matter: "1" and 1 are the same integer,
//   so the JSON that ToJson() and `dyad echo` print reads back, "nan" strings included):
//     - struct: a mapping of member names, nested structs as nested mappings; inherited members
//       (`struct B : A`) by their names, like B's own. An unknown key is an error that lists the
//       members; a key given twice is an error. Members left out take their zero value (0, 0.0,
//       false, '\0', "", empty sequence, first enumerator, arrays of zero values, structs of
//       zero values) unless EncodeOptions::require_all, which makes leaving one out an error;
//     - sequence<T> / sequence<T, N>: a YAML sequence of T values, at most N of them;
//     - fixed array T name[N]: a YAML sequence of exactly N values; T name[N][M] nests
//       ([[..M..], ..N..]);
//     - integers (octet, short, long, long long, their unsigned forms, int8..uint64): decimal
//       ("-12", "+7", "010" is 10) or hex ("0x1F", "-0x10"), within the type's range
//       ("300" for an octet is an error); text with a fraction or exponent ("1.5", "1e3") is an
//       error, not rounded;
//     - float, double: decimal numbers ("1", "-2.5", ".5", "6.02e23"), hex integers, "nan",
//       "inf", "-inf" ("+inf"; YAML's ".nan", ".inf", "-.inf" in their .NaN/.NAN, .Inf/.INF
//       spellings too). Read correctly rounded to the member's type; a finite value beyond the
//       type's largest ("1e39" for a float) is an error, one too small for it becomes 0 (or a
//       subnormal), as in C++;
//     - boolean: true, True, TRUE, false, False, FALSE (YAML 1.2; "yes", "on", "1" are errors);
//     - char: one byte of text ("Q"); "" is '\0' (as Decode() prints it);
//     - string, string<N>: the scalar's text, at most N bytes; a NUL inside is an error (CDR
//       strings end at the first NUL: fastcdr would cut the text there);
//     - enum: an enumerator's unqualified name ("BLUE") or a number that names one ("2").
//   Null (`~`, `null`, or nothing after the colon) is not a value of any type: leave the member
//   out for its zero value. YAML tags are ignored. Bounds (string<N>, sequence<T, N>) are
//   enforced: a longer value is not a value of the type (fastddsgen's fixed_string<N> would cut
//   it silently, readers may refuse it).
//
// ERRORS (a dyad::Status)
//   NotFound for a type the schema does not define as a struct (the message lists those it
//   does, as Decode's). InvalidArgument for a value that does not fit its member, the first one
//   found in declaration order (for a struct: its keys first, then its members):
//   "line L, column C: PATH: what is wrong", the position (1-based) of the offending YAML node
//   when yaml-cpp knows it (not for nodes built in code), PATH as Decode() spells it
//   ("header.stamp_ns", "human[3]", "corners[1].x"; "sample" for the root). Callers add the
//   source before it ("--data: line 1, column 5: ..."). For example (YAML, then the message):
//     {point: {tag: a, z: 1}}  line 1, column 18: point.z: unknown member of t::Point (members: tag, x, y)
//     {o: 300}                 line 1, column 5: o: 300 is out of range for octet (0..255)
//     {l: 1.5}                 line 1, column 5: l: expected an integer (long), found '1.5'
//     {b: yes}                 line 1, column 5: b: expected true or false (boolean), found 'yes'
//     {matrix: [[1, 2, 3]]}    line 1, column 10: matrix: expected 2 elements (a fixed array), 1 given
//     {two: [1, 2, 3]}         line 1, column 7: two: 3 elements exceed the sequence's bound of 2
//     {short_name: abcd}       line 1, column 14: short_name: 4 bytes exceed the string's bound of 3
//     {point: [1, 2]}          line 1, column 9: point: expected a mapping (the members of t::Point), found a sequence
//
// THREADS
//   Only reads the schema and the YAML; safe to call concurrently (with distinct or unchanging
//   nodes: yaml-cpp nodes are not thread-safe to modify).
//
// EXAMPLE
//   dyad::StatusOr<dyad::cdr::Schema> schema = dyad::cdr::Schema::Parse(idl_text);
//   ...
//   const YAML::Node fields = YAML::Load("{header: {source: cli}, x: 1.5, y: -2, engaged: true}");
//   dyad::StatusOr<std::vector<uint8_t>> sample =
//       dyad::cdr::EncodeYaml(*schema, "dyad::msg::HumanInput", fields);
//   if (!sample.ok()) { std::cerr << "--data: " << sample.status().message() << "\n"; return; }
//   // *sample: the bytes to write (header.sequence_number and stamp_ns are 0: not given).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <yaml-cpp/node/node.h>

#include <dyad/cdr_decoder.hpp>
#include <dyad/status.hpp>

namespace dyad::cdr {

struct EncodeOptions {
  // Every member must be given (in nested structs too): leaving one out is an error
  // ("header.stamp_ns: missing (every member is required)") instead of its zero value.
  bool require_all = false;
};

// Serializes one sample of the struct `type_name` (fully qualified, as Schema names types:
// "dyad::msg::HumanInput"; a leading "::" or a "#<hash>" suffix is allowed) with the 4-byte
// little-endian plain-CDR encapsulation header, taking member values from the YAML mapping
// `fields` (see INPUT above). The bytes, or the first problem (see ERRORS).
StatusOr<std::vector<uint8_t>> EncodeYaml(const Schema& schema, const std::string& type_name,
                                          const YAML::Node& fields, const EncodeOptions& options = {});

}  // namespace dyad::cdr
