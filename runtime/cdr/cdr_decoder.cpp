// Decode, DecodeRow, Columns and ToJson: a small interpreter over the op lists Schema::Parse
// compiled, and a compact JSON writer.
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "dyad/cdr_decoder.hpp"
#include "schema_impl.hpp"

namespace dyad::cdr {
namespace {

using internal::Op;
using internal::OpCode;
using internal::Prim;
using internal::SchemaImpl;
using internal::StructDef;

constexpr size_t kEncapsulationSize = 4;

bool IsNonFinite(std::string_view t) { return t == "nan" || t == "inf" || t == "-inf"; }

// Compact JSON into a string the caller owns.
class JsonWriter {
 public:
  void Reset(std::string* out) {
    out_ = out;
    first_.clear();
    after_key_ = false;
  }
  void BeginObject() { Open('{'); }
  void EndObject() { Close('}'); }
  void BeginArray() { Open('['); }
  void EndArray() { Close(']'); }
  void Key(std::string_view key) {
    Separate();
    String(key);
    out_->push_back(':');
    after_key_ = true;
  }
  void Value(std::string_view text, Field::Kind kind) {
    Separate();
    if (kind == Field::Kind::kBool || (kind == Field::Kind::kNumber && !IsNonFinite(text))) {
      out_->append(text);
    } else {
      String(text);
    }
  }

 private:
  void Open(char c) {
    Separate();
    out_->push_back(c);
    first_.push_back(1);
  }
  void Close(char c) {
    out_->push_back(c);
    first_.pop_back();
  }
  void Separate() {
    if (after_key_) {
      after_key_ = false;
    } else if (!first_.empty()) {
      if (!first_.back()) out_->push_back(',');
      first_.back() = 0;
    }
  }
  void String(std::string_view s) {
    static constexpr char kHex[] = "0123456789abcdef";
    out_->push_back('"');
    for (const char ch : s) {
      const auto c = static_cast<unsigned char>(ch);
      switch (c) {
        case '"': out_->append("\\\""); break;
        case '\\': out_->append("\\\\"); break;
        case '\n': out_->append("\\n"); break;
        case '\r': out_->append("\\r"); break;
        case '\t': out_->append("\\t"); break;
        case '\b': out_->append("\\b"); break;
        case '\f': out_->append("\\f"); break;
        default:
          if (c < 0x20) {
            const char esc[] = {'\\', 'u', '0', '0', kHex[c >> 4], kHex[c & 15]};
            out_->append(esc, sizeof esc);
          } else {
            out_->push_back(ch);
          }
      }
    }
    out_->push_back('"');
  }

  std::string* out_ = nullptr;
  // Per open container: 1 while nothing is written in it yet. A string for its inline buffer:
  // no allocation per sample for up to 15 nested containers (DecodeRow's JSON cells).
  std::string first_;
  bool after_key_ = false;
};

// Room for any number std::to_chars writes here (shortest double: at most 24 characters).
constexpr size_t kNumberBuffer = 48;

template <class T>
std::string_view FormatInt(char* buf, T v) {
  auto r = std::to_chars(buf, buf + kNumberBuffer, v);
  return std::string_view(buf, static_cast<size_t>(r.ptr - buf));
}

template <class T>
std::string_view FormatReal(char* buf, T v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v < 0 ? "-inf" : "inf";
  auto r = std::to_chars(buf, buf + kNumberBuffer, v);  // shortest form that reads back exactly
  return std::string_view(buf, static_cast<size_t>(r.ptr - buf));
}

inline uint8_t ByteSwap(uint8_t v) { return v; }
inline uint16_t ByteSwap(uint16_t v) { return __builtin_bswap16(v); }
inline uint32_t ByteSwap(uint32_t v) { return __builtin_bswap32(v); }
inline uint64_t ByteSwap(uint64_t v) { return __builtin_bswap64(v); }

// Walks a struct's ops over one payload, sending values either to a field list or to a row.
class Machine {
 public:
  Machine(const SchemaImpl& schema, const StructDef& def, const uint8_t* payload, size_t size,
          bool swap)
      : schema_(schema), ops_(def.ops), data_(payload), size_(size), swap_(swap) {}

  bool DecodeFields(std::vector<Field>* out) {
    fields_ = out;
    out->clear();
    return Run(0, static_cast<uint32_t>(ops_.size()));
  }

  bool DecodeRow(std::vector<std::string>* row) {
    row_ = row;
    const bool ok = Run(0, static_cast<uint32_t>(ops_.size()));
    row->resize(col_);
    return ok;
  }

  std::string& error() { return error_; }

 private:
  bool Run(uint32_t begin, uint32_t end) {
    for (uint32_t pc = begin; pc < end; ++pc) {
      const Op& op = ops_[pc];
      switch (op.code) {
        case OpCode::kPrim:
          if (!Primitive(op)) return false;
          break;
        case OpCode::kString:
          if (!String(op)) return false;
          break;
        case OpCode::kEnum:
          if (!Enum(op)) return false;
          break;
        case OpCode::kStruct: {
          const size_t saved = EnterPath(op.name);
          if (InJson()) {
            if (!op.name.empty()) json_.Key(op.name);
            json_.BeginObject();
          }
          if (!Run(pc + 1, op.end)) return false;
          if (InJson()) json_.EndObject();
          path_.resize(saved);
          pc = op.end - 1;
          break;
        }
        case OpCode::kSequence:
        case OpCode::kArray:
          if (!List(pc, op)) return false;
          pc = op.end - 1;
          break;
      }
    }
    return true;
  }

  bool List(uint32_t pc, const Op& op) {
    const bool sequence = op.code == OpCode::kSequence;
    const size_t saved = EnterPath(op.name);
    uint32_t count = op.arg;
    if (sequence && !Read(&count, {}, "sequence length")) return false;
    if (count > 0 && Left(pos_) / op.min_elem < count) {
      return Fail({}, pos_, std::string(sequence ? "sequence" : "array") + " of " +
                                std::to_string(count) + " elements needs at least " +
                                std::to_string(uint64_t{count} * op.min_elem) + " bytes, " +
                                std::to_string(Left(pos_)) + " left");
    }
    if (fields_ && sequence) {
      char buf[kNumberBuffer];
      Field& f = fields_->emplace_back();
      f.path = path_;
      f.value = FormatInt(buf, count);
      f.kind = Field::Kind::kSequence;
    }
    if (row_ && sequence && json_depth_ == 0) {
      std::string& cell = NextCell();
      cell.clear();
      json_.Reset(&cell);
    } else if (InJson() && !op.name.empty()) {
      json_.Key(op.name);
    }
    if (sequence) ++json_depth_;
    if (InJson()) json_.BeginArray();
    const size_t base = path_.size();
    for (uint32_t i = 0; i < count; ++i) {
      path_.resize(base);
      char buf[kNumberBuffer];
      path_ += '[';
      path_ += FormatInt(buf, i);
      path_ += ']';
      if (!Run(pc + 1, op.end)) return false;
    }
    if (InJson()) json_.EndArray();
    if (sequence) --json_depth_;
    path_.resize(saved);
    return true;
  }

  bool Primitive(const Op& op) {
    char buf[kNumberBuffer];
    std::string_view text;
    Field::Kind kind = Field::Kind::kNumber;
    const char* type = internal::PrimName(op.prim);
    switch (op.prim) {
      case Prim::kBool: {
        uint8_t v = 0;
        if (!Read(&v, op.name, type)) return false;
        if (v > 1) {
          return Fail(op.name, pos_ - 1,
                      "boolean byte is " + std::to_string(v) + " (must be 0 or 1)");
        }
        text = v ? "true" : "false";
        kind = Field::Kind::kBool;
        break;
      }
      case Prim::kChar: {
        uint8_t v = 0;
        if (!Read(&v, op.name, type)) return false;
        text = v ? std::string_view(reinterpret_cast<const char*>(data_ + pos_ - 1), 1)
                 : std::string_view();
        kind = Field::Kind::kString;
        break;
      }
      case Prim::kOctet:
      case Prim::kUInt8: {
        uint8_t v = 0;
        if (!Read(&v, op.name, type)) return false;
        text = FormatInt(buf, unsigned{v});
        break;
      }
      case Prim::kInt8: {
        uint8_t v = 0;
        if (!Read(&v, op.name, type)) return false;
        text = FormatInt(buf, int{static_cast<int8_t>(v)});
        break;
      }
      case Prim::kInt16:
      case Prim::kUInt16: {
        uint16_t v = 0;
        if (!Read(&v, op.name, type)) return false;
        text = op.prim == Prim::kInt16 ? FormatInt(buf, static_cast<int16_t>(v)) : FormatInt(buf, v);
        break;
      }
      case Prim::kInt32:
      case Prim::kUInt32: {
        uint32_t v = 0;
        if (!Read(&v, op.name, type)) return false;
        text = op.prim == Prim::kInt32 ? FormatInt(buf, static_cast<int32_t>(v)) : FormatInt(buf, v);
        break;
      }
      case Prim::kInt64:
      case Prim::kUInt64: {
        uint64_t v = 0;
        if (!Read(&v, op.name, type)) return false;
        text = op.prim == Prim::kInt64 ? FormatInt(buf, static_cast<int64_t>(v)) : FormatInt(buf, v);
        break;
      }
      case Prim::kFloat: {
        uint32_t v = 0;
        if (!Read(&v, op.name, type)) return false;
        text = FormatReal(buf, std::bit_cast<float>(v));
        break;
      }
      case Prim::kDouble: {
        uint64_t v = 0;
        if (!Read(&v, op.name, type)) return false;
        text = FormatReal(buf, std::bit_cast<double>(v));
        break;
      }
    }
    Emit(op.name, text, kind);
    return true;
  }

  bool String(const Op& op) {
    uint32_t length = 0;
    if (!Read(&length, op.name, "string length")) return false;
    if (length > Left(pos_)) {
      return Fail(op.name, pos_, "truncated: string of " + std::to_string(length) + " bytes, " +
                                     std::to_string(Left(pos_)) + " left");
    }
    const char* s = reinterpret_cast<const char*>(data_ + pos_);
    pos_ += length;
    size_t n = length;
    if (n > 0 && s[n - 1] == '\0') --n;  // the NUL; fastcdr tolerates its absence, so do we
    Emit(op.name, std::string_view(s, n), Field::Kind::kString);
    return true;
  }

  bool Enum(const Op& op) {
    uint32_t v = 0;
    if (!Read(&v, op.name, "enum")) return false;
    const std::vector<std::string>& names = schema_.enums[op.arg].enumerators;
    if (v < names.size()) {
      Emit(op.name, names[v], Field::Kind::kString);
    } else {
      char buf[kNumberBuffer];
      Emit(op.name, FormatInt(buf, v), Field::Kind::kNumber);
    }
    return true;
  }

  // Reads one unsigned integer of sizeof(U) bytes, aligned to its size, in the payload's byte
  // order.
  template <class U>
  bool Read(U* v, std::string_view name, const char* type) {
    static_assert(std::is_unsigned_v<U>);
    const size_t at = (pos_ + (sizeof(U) - 1)) & ~(sizeof(U) - 1);
    if (at > size_ || size_ - at < sizeof(U)) {
      return Fail(name, at, std::string("truncated: ") + type + " needs " +
                                  std::to_string(sizeof(U)) + " bytes, " +
                                  std::to_string(Left(at)) + " left");
    }
    std::memcpy(v, data_ + at, sizeof(U));
    if (swap_) *v = ByteSwap(*v);
    pos_ = at + sizeof(U);
    return true;
  }

  size_t Left(size_t at) const { return at < size_ ? size_ - at : 0; }

  // Sends one value to the fields or the row.
  void Emit(std::string_view name, std::string_view text, Field::Kind kind) {
    if (fields_) {
      Field& f = fields_->emplace_back();
      f.path.reserve(path_.size() + 1 + name.size());
      f.path = path_;
      AppendName(&f.path, name);
      f.value.assign(text);
      f.kind = kind;
    } else if (!InJson()) {
      NextCell().assign(text);
    } else {
      if (!name.empty()) json_.Key(name);
      json_.Value(text, kind);
    }
  }

  bool InJson() const { return json_depth_ > 0 && row_ != nullptr; }

  std::string& NextCell() {
    if (col_ == row_->size()) row_->emplace_back();
    return (*row_)[col_++];
  }

  static void AppendName(std::string* path, std::string_view name) {
    if (name.empty()) return;
    if (!path->empty()) path->push_back('.');
    path->append(name);
  }
  size_t EnterPath(std::string_view name) {
    const size_t saved = path_.size();
    AppendName(&path_, name);
    return saved;
  }

  bool Fail(std::string_view name, size_t offset, const std::string& message) {
    std::string path = path_;
    AppendName(&path, name);
    error_ = "offset " + std::to_string(offset) + " (" + (path.empty() ? "sample" : path) +
             "): " + message;
    return false;
  }

  const SchemaImpl& schema_;
  const std::vector<Op>& ops_;
  const uint8_t* data_;  // the payload after the encapsulation header
  size_t size_;
  bool swap_;
  size_t pos_ = 0;
  std::string path_;  // of the container being decoded
  std::string error_;
  std::vector<Field>* fields_ = nullptr;
  std::vector<std::string>* row_ = nullptr;
  size_t col_ = 0;
  int json_depth_ = 0;  // sequences entered (row mode: > 0 means writing a JSON cell)
  JsonWriter json_;
};

// Finds the struct and checks the encapsulation header. Sets *swap when the payload's byte order
// differs from this machine's.
StatusOr<const StructDef*> Prepare(const Schema& schema, const std::string& root_type, const uint8_t* data,
                                   size_t size, bool* swap) {
  const SchemaImpl& impl = *ImplOf(schema);
  const StructDef* def = impl.FindStruct(root_type);
  if (!def) return impl.UnknownStruct(root_type);
  if (size < kEncapsulationSize || data == nullptr) {
    return Status::DataLoss("sample of " + std::to_string(size) + " bytes is shorter than the 4-byte encapsulation header");
  }
  if (data[0] != 0 || data[1] > 1) {
    static constexpr char kHex[] = "0123456789abcdef";
    const char id[] = {'0', 'x', kHex[data[0] >> 4], kHex[data[0] & 15], kHex[data[1] >> 4],
                       kHex[data[1] & 15], 0};
    return Status::Unimplemented(std::string("encapsulation ") + id +
                                 " is not supported (only plain CDR: 0x0000 big endian, 0x0001 little endian)");
  }
  const bool little = data[1] == 1;
  *swap = little != (std::endian::native == std::endian::little);
  return def;
}

void AddColumns(const std::vector<Op>& ops, uint32_t begin, uint32_t end, std::string* path,
                std::vector<std::string>* columns) {
  for (uint32_t pc = begin; pc < end; ++pc) {
    const Op& op = ops[pc];
    const size_t saved = path->size();
    if (!op.name.empty()) {
      if (!path->empty()) path->push_back('.');
      path->append(op.name);
    }
    switch (op.code) {
      case OpCode::kPrim:
      case OpCode::kString:
      case OpCode::kEnum:
      case OpCode::kSequence:
        columns->push_back(*path);
        break;
      case OpCode::kStruct:
        AddColumns(ops, pc + 1, op.end, path, columns);
        break;
      case OpCode::kArray: {
        const size_t base = path->size();
        for (uint32_t i = 0; i < op.arg; ++i) {
          path->resize(base);
          path->push_back('[');
          path->append(std::to_string(i));
          path->push_back(']');
          AddColumns(ops, pc + 1, op.end, path, columns);
        }
        break;
      }
    }
    if (op.code != OpCode::kPrim && op.code != OpCode::kString && op.code != OpCode::kEnum) {
      pc = op.end - 1;
    }
    path->resize(saved);
  }
}

// One step of a field path: a member name or an element index ("3" of "[3]").
struct PathToken {
  std::string_view text;
  bool index = false;
  bool operator==(const PathToken&) const = default;
};

void SplitPath(std::string_view path, std::vector<PathToken>* tokens) {
  tokens->clear();
  size_t i = 0;
  while (i < path.size()) {
    if (path[i] == '.') {
      ++i;
    } else if (path[i] == '[') {
      size_t close = path.find(']', i);
      if (close == std::string_view::npos) close = path.size();
      tokens->push_back({path.substr(i + 1, close - i - 1), true});
      i = close + 1;
    } else {
      size_t e = path.find_first_of(".[", i);
      if (e == std::string_view::npos) e = path.size();
      tokens->push_back({path.substr(i, e - i), false});
      i = e;
    }
  }
}

}  // namespace

Status Decode(const Schema& schema, const std::string& root_type, const uint8_t* data, size_t size,
              std::vector<Field>* out) {
  bool swap = false;
  StatusOr<const StructDef*> def = Prepare(schema, root_type, data, size, &swap);
  if (!def.ok()) {
    out->clear();
    return def.status();
  }
  Machine m(*ImplOf(schema), **def, data + kEncapsulationSize, size - kEncapsulationSize, swap);
  if (!m.DecodeFields(out)) return Status::DataLoss(std::move(m.error()));
  return Status::OK();
}

Status DecodeRow(const Schema& schema, const std::string& root_type, const uint8_t* data, size_t size,
                 std::vector<std::string>* row) {
  bool swap = false;
  StatusOr<const StructDef*> def = Prepare(schema, root_type, data, size, &swap);
  if (!def.ok()) {
    row->clear();
    return def.status();
  }
  Machine m(*ImplOf(schema), **def, data + kEncapsulationSize, size - kEncapsulationSize, swap);
  if (!m.DecodeRow(row)) return Status::DataLoss(std::move(m.error()));
  return Status::OK();
}

std::vector<std::string> Columns(const Schema& schema, const std::string& root_type) {
  std::vector<std::string> columns;
  const StructDef* def = ImplOf(schema)->FindStruct(root_type);
  if (!def) return columns;
  std::string path;
  AddColumns(def->ops, 0, static_cast<uint32_t>(def->ops.size()), &path, &columns);
  return columns;
}

std::string ToJson(const std::vector<Field>& fields) {
  std::string out;
  JsonWriter w;
  w.Reset(&out);
  w.BeginObject();
  struct Open {
    PathToken token;
    bool array;
  };
  std::vector<Open> open;  // containers open below the root object
  std::vector<PathToken> tokens;
  for (const Field& f : fields) {
    // A non-empty sequence shows through its elements; an empty one is written as [].
    if (f.kind == Field::Kind::kSequence && f.value != "0") continue;
    SplitPath(f.path, &tokens);
    if (tokens.empty()) continue;
    const size_t parents = tokens.size() - 1;
    size_t keep = 0;
    while (keep < open.size() && keep < parents && open[keep].token == tokens[keep]) ++keep;
    while (open.size() > keep) {
      if (open.back().array) w.EndArray(); else w.EndObject();
      open.pop_back();
    }
    for (size_t j = keep; j < parents; ++j) {
      if (!tokens[j].index) w.Key(tokens[j].text);
      const bool array = tokens[j + 1].index;
      if (array) w.BeginArray(); else w.BeginObject();
      open.push_back({tokens[j], array});
    }
    if (!tokens.back().index) w.Key(tokens.back().text);
    if (f.kind == Field::Kind::kSequence) {
      w.BeginArray();
      w.EndArray();
    } else {
      w.Value(f.value, f.kind);
    }
  }
  while (!open.empty()) {
    if (open.back().array) w.EndArray(); else w.EndObject();
    open.pop_back();
  }
  w.EndObject();
  return out;
}

}  // namespace dyad::cdr
