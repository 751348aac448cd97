// EncodeYaml: walks the type graph Schema::Parse built alongside the YAML, appending the wire
// form of each value (the contract is dyad/cdr_encoder.hpp).
#include "dyad/cdr_encoder.hpp"

#include <bit>
#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "schema_impl.hpp"

namespace dyad::cdr {
namespace {

using internal::EnumDef;
using internal::Member;
using internal::Prim;
using internal::PrimSize;
using internal::SchemaImpl;
using internal::StructDef;
using internal::TypeNode;

// Plain CDR, little endian, no options: what Fast DDS writes on a little-endian host.
constexpr uint8_t kEncapsulation[] = {0x00, 0x01, 0x00, 0x00};
constexpr size_t kEncapsulationSize = sizeof kEncapsulation;

// The text of a scalar in a message, cut short so a long value cannot drown it.
std::string Quote(const std::string& text) {
  constexpr size_t kMax = 40;
  return "'" + (text.size() <= kMax ? text : text.substr(0, kMax) + "...") + "'";
}

// What the YAML gave instead of what was expected.
std::string Found(const YAML::Node& node) {
  if (!node.IsDefined()) return "nothing";
  switch (node.Type()) {
    case YAML::NodeType::Null: return "null";
    case YAML::NodeType::Scalar: return Quote(node.Scalar());
    case YAML::NodeType::Sequence: return "a sequence";
    case YAML::NodeType::Map: return "a mapping";
    case YAML::NodeType::Undefined: break;
  }
  return "nothing";
}

// YAML 1.2 core integers: [-+]?[0-9]+ (decimal, leading zeros allowed) or [-+]?0x[0-9a-fA-F]+.
enum class IntText { kOk, kNotInteger, kTooLarge };

IntText ParseInteger(std::string_view text, bool* negative, uint64_t* magnitude, bool* hex = nullptr) {
  *negative = false;
  if (!text.empty() && (text[0] == '-' || text[0] == '+')) {
    *negative = text[0] == '-';
    text.remove_prefix(1);
  }
  int base = 10;
  if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
    base = 16;
    text.remove_prefix(2);
  }
  if (hex) *hex = base == 16;
  // from_chars takes no sign here (we did) and nothing but digits must follow.
  if (text.empty() || text[0] == '-' || text[0] == '+') return IntText::kNotInteger;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), *magnitude, base);
  if (end != text.data() + text.size()) return IntText::kNotInteger;
  if (ec == std::errc::result_out_of_range) return IntText::kTooLarge;
  return ec == std::errc() ? IntText::kOk : IntText::kNotInteger;
}

// Range of an integer primitive.
struct IntRange {
  int64_t min;
  uint64_t max;
};

IntRange RangeOf(Prim p) {
  switch (p) {
    case Prim::kOctet: case Prim::kUInt8: return {0, 0xff};
    case Prim::kInt8: return {-128, 127};
    case Prim::kInt16: return {-32768, 32767};
    case Prim::kUInt16: return {0, 0xffff};
    case Prim::kInt32: return {std::numeric_limits<int32_t>::min(), std::numeric_limits<int32_t>::max()};
    case Prim::kUInt32: return {0, std::numeric_limits<uint32_t>::max()};
    case Prim::kInt64: return {std::numeric_limits<int64_t>::min(), std::numeric_limits<int64_t>::max()};
    case Prim::kUInt64: return {0, std::numeric_limits<uint64_t>::max()};
    default: return {0, 0};  // not an integer
  }
}

enum class RealText { kOk, kNotNumber, kTooLarge };

// float or double text (see INPUT in the header), correctly rounded to T.
template <class T>
RealText ParseReal(std::string_view text, T* out) {
  if (text == "nan" || text == ".nan" || text == ".NaN" || text == ".NAN") {
    *out = std::numeric_limits<T>::quiet_NaN();
    return RealText::kOk;
  }
  bool negative = false;
  std::string_view u = text;  // without its sign
  if (!u.empty() && (u[0] == '-' || u[0] == '+')) {
    negative = u[0] == '-';
    u.remove_prefix(1);
  }
  if (u == "inf" || u == ".inf" || u == ".Inf" || u == ".INF") {
    *out = negative ? -std::numeric_limits<T>::infinity() : std::numeric_limits<T>::infinity();
    return RealText::kOk;
  }
  bool hex = false, int_negative = false;
  uint64_t magnitude = 0;
  if (const IntText i = ParseInteger(text, &int_negative, &magnitude, &hex); hex) {
    if (i == IntText::kNotInteger) return RealText::kNotNumber;
    if (i == IntText::kTooLarge) return RealText::kTooLarge;
    const T v = static_cast<T>(magnitude);  // rounds to nearest
    *out = int_negative ? -v : v;
    return RealText::kOk;
  }
  // from_chars would also take "inf", "nan(...)", "infinity": only digits or a '.' may start.
  if (u.empty() || !((u[0] >= '0' && u[0] <= '9') || u[0] == '.')) return RealText::kNotNumber;
  const char* const end = u.data() + u.size();
  T v = 0;
  const auto [ptr, ec] = std::from_chars(u.data(), end, v);
  if (ptr != end) return RealText::kNotNumber;
  if (ec == std::errc::result_out_of_range) {
    // Too large or too small for T: only too large is an error; too small is zero, as in C++.
    // A wider type tells which; beyond even long double, the exponent's sign does.
    long double wide = 0;
    bool too_large = false;
    if (std::from_chars(u.data(), end, wide).ec == std::errc()) {
      too_large = std::fabs(wide) > std::numeric_limits<T>::max();
    } else {
      const size_t e = u.find_first_of("eE");  // from_chars read it all: a digit or sign follows
      too_large = e == std::string_view::npos || u[e + 1] != '-';
    }
    if (too_large) return RealText::kTooLarge;
    v = 0;
  } else if (ec != std::errc()) {
    return RealText::kNotNumber;
  }
  *out = negative ? -v : v;
  return RealText::kOk;
}

// The shortest text that reads back as `v`.
template <class T>
std::string RealToString(T v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string MemberList(const StructDef& def) {
  std::string list;
  for (const Member& m : def.members) list += (list.empty() ? "" : ", ") + m.name;
  return list;
}

// Appends one sample's wire form. Every function returns false on the first problem, which
// error() then holds.
class Encoder {
 public:
  Encoder(const SchemaImpl& schema, const EncodeOptions& options)
      : schema_(schema), options_(options), out_(std::begin(kEncapsulation), std::end(kEncapsulation)) {}

  bool Root(const StructDef& def, const YAML::Node& fields) { return Struct(def, fields); }

  std::vector<uint8_t>& bytes() { return out_; }
  std::string& error() { return error_; }

 private:
  bool Value(int node, const YAML::Node& v) {
    const TypeNode& n = schema_.nodes[node];
    switch (n.kind) {
      case TypeNode::Kind::kPrim:
        return Primitive(n.prim, v);
      case TypeNode::Kind::kString:
        return String(n, v);
      case TypeNode::Kind::kEnum:
        return Enum(schema_.enums[n.def], v);
      case TypeNode::Kind::kStruct:
        return Struct(schema_.structs[n.def], v);
      case TypeNode::Kind::kSequence:
      case TypeNode::Kind::kArray:
        return List(n, v);
    }
    return true;
  }

  // The value of a member left out: zeros, "" and empty sequences (a default-constructed
  // fastddsgen type).
  void Zero(int node) {
    const TypeNode& n = schema_.nodes[node];
    switch (n.kind) {
      case TypeNode::Kind::kPrim:
        Put(0, PrimSize(n.prim));
        return;
      case TypeNode::Kind::kString:
        Put(1, 4);  // length 1: just the NUL
        out_.push_back(0);
        return;
      case TypeNode::Kind::kEnum:
      case TypeNode::Kind::kSequence:
        Put(0, 4);
        return;
      case TypeNode::Kind::kStruct:
        for (const Member& m : schema_.structs[n.def].members) Zero(m.node);
        return;
      case TypeNode::Kind::kArray:
        for (uint32_t i = 0; i < n.size; ++i) Zero(n.elem);
        return;
    }
  }

  bool Struct(const StructDef& def, const YAML::Node& v) {
    if (!v.IsDefined() || !v.IsMap()) {
      return Fail(v, "expected a mapping (the members of " + def.name + "), found " + Found(v));
    }
    // Keys first: each must name a member, once.
    std::vector<std::optional<YAML::Node>> given(def.members.size());
    for (const auto& entry : v) {
      const YAML::Node key = entry.first;
      if (!key.IsScalar()) return Fail(key, "expected member names as keys, found " + Found(key));
      size_t m = 0;
      while (m < def.members.size() && def.members[m].name != key.Scalar()) ++m;
      const size_t saved = Enter(key.Scalar());
      if (m == def.members.size()) {
        return Fail(key, "unknown member of " + def.name + " (members: " + MemberList(def) + ")");
      }
      if (given[m]) return Fail(key, "given twice");
      path_.resize(saved);
      given[m] = entry.second;
    }
    for (size_t m = 0; m < def.members.size(); ++m) {
      const size_t saved = Enter(def.members[m].name);
      if (given[m]) {
        if (!Value(def.members[m].node, *given[m])) return false;
      } else if (options_.require_all) {
        return Fail(v, "missing (every member is required)");
      } else {
        Zero(def.members[m].node);
      }
      path_.resize(saved);
    }
    return true;
  }

  bool List(const TypeNode& n, const YAML::Node& v) {
    const bool sequence = n.kind == TypeNode::Kind::kSequence;
    if (!v.IsSequence()) return Fail(v, "expected a sequence, found " + Found(v));
    const size_t count = v.size();
    if (sequence && n.size > 0 && count > n.size) {
      return Fail(v, std::to_string(count) + " elements exceed the sequence's bound of " + std::to_string(n.size));
    }
    if (!sequence && count != n.size) {
      return Fail(v, "expected " + std::to_string(n.size) + " element" + (n.size == 1 ? "" : "s") +
                         " (a fixed array), " + std::to_string(count) + " given");
    }
    if (sequence) Put(count, 4);
    const size_t saved = path_.size();
    size_t i = 0;
    for (const YAML::Node& element : v) {
      path_ += '[';
      path_ += std::to_string(i++);
      path_ += ']';
      if (!Value(n.elem, element)) return false;
      path_.resize(saved);
    }
    return true;
  }

  bool String(const TypeNode& n, const YAML::Node& v) {
    if (!v.IsScalar()) {
      return Fail(v, "expected a string, found " + Found(v) +
                         (v.IsNull() ? " (\"\" is the empty string)" : ""));
    }
    const std::string& s = v.Scalar();
    if (n.size > 0 && s.size() > n.size) {
      return Fail(v, std::to_string(s.size()) + " bytes exceed the string's bound of " + std::to_string(n.size));
    }
    if (s.find('\0') != std::string::npos) {
      return Fail(v, "contains a NUL character (a CDR string ends at the first NUL)");
    }
    Put(s.size() + 1, 4);
    out_.insert(out_.end(), s.begin(), s.end());
    out_.push_back(0);
    return true;
  }

  bool Enum(const EnumDef& def, const YAML::Node& v) {
    const std::vector<std::string>& names = def.enumerators;
    std::string list;
    for (const std::string& e : names) list += (list.empty() ? "" : ", ") + e;
    const std::string what = "an enumerator of " + def.name + " (" + list + "; or 0.." +
                             std::to_string(names.size() - 1) + ")";
    if (!v.IsScalar()) return Fail(v, "expected " + what + ", found " + Found(v));
    const std::string& text = v.Scalar();
    for (size_t i = 0; i < names.size(); ++i) {
      if (names[i] == text) {
        Put(i, 4);
        return true;
      }
    }
    bool negative = false;
    uint64_t number = 0;
    if (ParseInteger(text, &negative, &number) == IntText::kOk && (!negative || number == 0) &&
        number < names.size()) {
      Put(number, 4);
      return true;
    }
    return Fail(v, "expected " + what + ", found " + Quote(text));
  }

  bool Primitive(Prim p, const YAML::Node& v) {
    const char* type = internal::PrimName(p);
    switch (p) {
      case Prim::kBool: {
        const std::string what = "true or false (boolean)";
        if (!v.IsScalar()) return Fail(v, "expected " + what + ", found " + Found(v));
        const std::string& t = v.Scalar();
        if (t == "true" || t == "True" || t == "TRUE") {
          Put(1, 1);
        } else if (t == "false" || t == "False" || t == "FALSE") {
          Put(0, 1);
        } else {
          return Fail(v, "expected " + what + ", found " + Found(v));
        }
        return true;
      }
      case Prim::kChar: {
        if (!v.IsScalar() || v.Scalar().size() > 1) {
          return Fail(v, "expected one character (char), found " + Found(v));
        }
        Put(v.Scalar().empty() ? 0 : static_cast<uint8_t>(v.Scalar()[0]), 1);
        return true;
      }
      case Prim::kFloat: {
        float f = 0;
        if (!Real(v, type, &f)) return false;
        Put(std::bit_cast<uint32_t>(f), 4);
        return true;
      }
      case Prim::kDouble: {
        double d = 0;
        if (!Real(v, type, &d)) return false;
        Put(std::bit_cast<uint64_t>(d), 8);
        return true;
      }
      default:
        break;
    }
    const std::string what = std::string("an integer (") + type + ")";
    if (!v.IsScalar()) return Fail(v, "expected " + what + ", found " + Found(v));
    const std::string& text = v.Scalar();
    bool negative = false;
    uint64_t magnitude = 0;
    const IntText parsed = ParseInteger(text, &negative, &magnitude);
    if (parsed == IntText::kNotInteger) return Fail(v, "expected " + what + ", found " + Quote(text));
    const IntRange range = RangeOf(p);
    // The magnitude of the most negative value, computed without overflowing int64.
    const uint64_t min_magnitude = range.min < 0 ? uint64_t{0} - static_cast<uint64_t>(range.min) : 0;
    if (parsed == IntText::kTooLarge || (negative ? magnitude > min_magnitude : magnitude > range.max)) {
      return Fail(v, text + " is out of range for " + type + " (" + std::to_string(range.min) + ".." +
                         std::to_string(range.max) + ")");
    }
    // Two's complement: the low bytes of the 64-bit value are the narrower type's.
    Put(negative ? uint64_t{0} - magnitude : magnitude, PrimSize(p));
    return true;
  }

  template <class T>
  bool Real(const YAML::Node& v, const char* type, T* out) {
    const std::string what = std::string("a number (") + type + ")";
    if (!v.IsScalar()) return Fail(v, "expected " + what + ", found " + Found(v));
    switch (ParseReal(v.Scalar(), out)) {
      case RealText::kOk:
        return true;
      case RealText::kNotNumber:
        return Fail(v, "expected " + what + ", found " + Quote(v.Scalar()));
      case RealText::kTooLarge:
        break;
    }
    return Fail(v, v.Scalar() + " is out of range for " + type + " (largest finite: " +
                       RealToString(std::numeric_limits<T>::max()) + ")");
  }

  // Appends the low `size` bytes of `v`, little endian, aligned to `size` from the first byte
  // after the encapsulation header (fastcdr's alignment; the padding is zero).
  void Put(uint64_t v, size_t size) {
    while ((out_.size() - kEncapsulationSize) % size != 0) out_.push_back(0);
    for (size_t i = 0; i < size; ++i) out_.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }

  size_t Enter(const std::string& name) {
    const size_t saved = path_.size();
    if (!path_.empty()) path_ += '.';
    path_ += name;
    return saved;
  }

  bool Fail(const YAML::Node& at, const std::string& message) {
    error_.clear();
    // Nodes built in code have no position.
    if (at.IsDefined() && !at.Mark().is_null()) {
      error_ = "line " + std::to_string(at.Mark().line + 1) + ", column " +
               std::to_string(at.Mark().column + 1) + ": ";
    }
    error_ += (path_.empty() ? "sample" : path_) + ": " + message;
    return false;
  }

  const SchemaImpl& schema_;
  const EncodeOptions& options_;
  std::vector<uint8_t> out_;
  std::string path_;  // of the value being encoded
  std::string error_;
};

}  // namespace

StatusOr<std::vector<uint8_t>> EncodeYaml(const Schema& schema, const std::string& type_name,
                                          const YAML::Node& fields, const EncodeOptions& options) {
  const SchemaImpl& impl = *ImplOf(schema);
  const StructDef* def = impl.FindStruct(type_name);
  if (!def) return impl.UnknownStruct(type_name);
  Encoder encoder(impl, options);
  try {
    if (!encoder.Root(*def, fields)) return Status::InvalidArgument(std::move(encoder.error()));
  } catch (const YAML::Exception& e) {
    // yaml-cpp throws on invalid nodes only, which Struct and Fail check for; caught all the
    // same, since nothing may throw across dyad's API.
    return Status::InvalidArgument(e.what());
  }
  return std::move(encoder.bytes());
}

}  // namespace dyad::cdr
