// Internal to dyad_cdr: the parsed type graph and the compiled decoding programs.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "dyad/cdr_decoder.hpp"

namespace dyad::cdr::internal {

enum class Prim : uint8_t {
  kBool, kOctet, kChar, kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kInt64, kUInt64,
  kFloat, kDouble,
};

// Wire size (= alignment) of a primitive.
inline uint32_t PrimSize(Prim p) {
  switch (p) {
    case Prim::kBool: case Prim::kOctet: case Prim::kChar: case Prim::kInt8: case Prim::kUInt8:
      return 1;
    case Prim::kInt16: case Prim::kUInt16:
      return 2;
    case Prim::kInt32: case Prim::kUInt32: case Prim::kFloat:
      return 4;
    case Prim::kInt64: case Prim::kUInt64: case Prim::kDouble:
      return 8;
  }
  return 1;
}

// IDL spelling of a primitive, for error messages.
const char* PrimName(Prim p);

// One node of the type graph. Anonymous types (sequence<T>, arrays) get nodes of their own.
struct TypeNode {
  enum class Kind : uint8_t { kPrim, kString, kSequence, kArray, kStruct, kEnum };
  Kind kind = Kind::kPrim;
  Prim prim = Prim::kBool;  // kPrim
  uint32_t size = 0;        // kArray: element count; kString/kSequence: bound (0: unbounded)
  int elem = -1;            // kSequence/kArray: element node
  int def = -1;             // kStruct: index in structs; kEnum: index in enums
  int depth = 1;            // levels of nesting, this one included
};

struct Member {
  std::string name;
  int node = -1;
};

// How a struct is decoded: a flat list of ops. Leaf ops read one value; kStruct, kSequence and
// kArray ops own the ops (pc, end) that follow them, which decode one member / element.
enum class OpCode : uint8_t { kPrim, kString, kEnum, kStruct, kSequence, kArray };

struct Op {
  OpCode code = OpCode::kPrim;
  Prim prim = Prim::kBool;  // kPrim
  uint32_t arg = 0;         // kEnum: enum index; kArray: element count
  uint32_t min_elem = 1;    // kSequence/kArray: fewest bytes one element takes on the wire (>= 1)
  uint32_t end = 0;         // kStruct/kSequence/kArray: index one past the last op they own
  std::string name;         // member name; empty for a sequence or array element
};

struct StructDef {
  std::string name;  // qualified
  int line = 0;
  std::vector<Member> members;
  // Compiled once parsing is done, in definition order (members only use earlier structs).
  int depth = 1;          // levels of nesting, this one included
  uint32_t min_size = 0;  // fewest bytes one value takes on the wire (saturating)
  std::vector<Op> ops;
};

struct EnumDef {
  std::string name;  // qualified
  std::vector<std::string> enumerators;
};

struct SchemaImpl {
  std::vector<TypeNode> nodes;
  std::vector<StructDef> structs;
  std::vector<EnumDef> enums;
  // Qualified name -> index in structs; looked up by string_view without allocating.
  struct NameHash {
    using is_transparent = void;
    size_t operator()(std::string_view s) const { return std::hash<std::string_view>{}(s); }
  };
  std::unordered_map<std::string, int, NameHash, std::equal_to<>> struct_index;

  // The struct named `name` ("a::B", "::a::B" or "a::B#hash"), or null.
  const StructDef* FindStruct(const std::string& name) const;
  // NotFound for a `name` FindStruct does not know, listing the structs there are (the error of
  // Decode and EncodeYaml alike).
  Status UnknownStruct(const std::string& name) const;
};

}  // namespace dyad::cdr::internal

namespace dyad::cdr {
// The parsed schema behind `schema` (never null). Friend of Schema.
const internal::SchemaImpl* ImplOf(const Schema& schema);
}  // namespace dyad::cdr
