// Schema::Parse: a small IDL reader (the subset documented in dyad/cdr_decoder.hpp) and the
// compiler that turns each struct into the flat op list the decoder walks.
#include <algorithm>
#include <charconv>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "dyad/cdr_decoder.hpp"
#include "schema_impl.hpp"

namespace dyad::cdr {
namespace internal {

const char* PrimName(Prim p) {
  switch (p) {
    case Prim::kBool: return "boolean";
    case Prim::kOctet: return "octet";
    case Prim::kChar: return "char";
    case Prim::kInt8: return "int8";
    case Prim::kUInt8: return "uint8";
    case Prim::kInt16: return "short";
    case Prim::kUInt16: return "unsigned short";
    case Prim::kInt32: return "long";
    case Prim::kUInt32: return "unsigned long";
    case Prim::kInt64: return "long long";
    case Prim::kUInt64: return "unsigned long long";
    case Prim::kFloat: return "float";
    case Prim::kDouble: return "double";
  }
  return "?";
}

const StructDef* SchemaImpl::FindStruct(const std::string& name) const {
  std::string_view n = name;
  if (n.starts_with("::")) n.remove_prefix(2);
  if (size_t hash = n.find('#'); hash != std::string_view::npos) n = n.substr(0, hash);
  auto it = struct_index.find(n);
  return it == struct_index.end() ? nullptr : &structs[it->second];
}

Status SchemaImpl::UnknownStruct(const std::string& name) const {
  std::string known;
  for (const StructDef& s : structs) known += (known.empty() ? "" : ", ") + s.name;
  return Status::NotFound("unknown type '" + name + "' (" +
                          (known.empty() ? "the schema defines no structs" : "the schema defines: " + known) + ")");
}

namespace {

// Thrown inside the parser only; Parse turns it into "line N: message".
struct ParseError {
  int line;
  std::string message;
  bool unsupported = false;  // valid IDL this reader does not support (Status::Unimplemented)
};

struct Token {
  enum class Type { kIdent, kNumber, kPunct, kLiteral, kEnd };
  Type type = Type::kEnd;
  std::string text;
  int line = 0;
};

bool IsIdentStart(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool IsIdentChar(char c) { return IsIdentStart(c) || (c >= '0' && c <= '9'); }
bool IsDigit(char c) { return c >= '0' && c <= '9'; }

// Splits IDL text into tokens, dropping comments and the preprocessor lines we ignore.
// A preprocessor line (after its '#'): include, pragma and include guards are ignored; anything
// else is an error, as we do not preprocess.
void CheckDirective(std::string_view directive, int line) {
  std::vector<std::string_view> words;
  auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  for (size_t k = 0; k < directive.size();) {
    while (k < directive.size() && blank(directive[k])) ++k;
    const size_t b = k;
    while (k < directive.size() && !blank(directive[k])) ++k;
    if (k > b) words.push_back(directive.substr(b, k - b));
  }
  const std::string_view word = words.empty() ? std::string_view() : words[0];
  const bool ignored = word == "include" || word == "pragma" || word == "endif" ||
                       ((word == "ifndef" || word == "define") && words.size() == 2);
  if (!ignored) {
    throw ParseError{line, "preprocessor directive '#" + std::string(word) +
                               "' is not supported (only #include, #pragma and include "
                               "guards, which are ignored)",
                     true};
  }
}

// The token that starts at s[*i] (not blank, not a comment); *i moves past it.
Token ReadToken(const std::string& s, size_t* i, int line) {
  const size_t n = s.size();
  const char c = s[*i];
  Token t;
  t.line = line;
  const size_t b = *i;
  if (IsIdentStart(c)) {
    while (*i < n && IsIdentChar(s[*i])) ++*i;
    t.type = Token::Type::kIdent;
  } else if (IsDigit(c)) {
    while (*i < n && (IsIdentChar(s[*i]) || s[*i] == '.')) ++*i;
    t.type = Token::Type::kNumber;
  } else if (c == '"' || c == '\'') {
    ++*i;
    while (*i < n && s[*i] != c && s[*i] != '\n') *i += (s[*i] == '\\' && *i + 1 < n) ? 2 : 1;
    if (*i >= n || s[*i] != c) throw ParseError{line, "unterminated literal"};
    ++*i;
    t.type = Token::Type::kLiteral;
  } else {
    *i += (c == ':' && *i + 1 < n && s[*i + 1] == ':') ? 2 : 1;  // "::" or one character
    t.type = Token::Type::kPunct;
  }
  t.text = s.substr(b, *i - b);
  return t;
}

std::vector<Token> Tokenize(const std::string& s) {
  std::vector<Token> tokens;
  int line = 1;
  bool line_start = true;  // only whitespace so far on this line
  size_t i = 0;
  const size_t n = s.size();
  while (i < n) {
    const char c = s[i];
    if (c == '\n') {
      ++line;
      line_start = true;
      ++i;
    } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
      ++i;
    } else if (c == '/' && i + 1 < n && s[i + 1] == '/') {
      while (i < n && s[i] != '\n') ++i;
    } else if (c == '/' && i + 1 < n && s[i + 1] == '*') {
      const int start = line;
      for (i += 2; i + 1 < n && !(s[i] == '*' && s[i + 1] == '/'); ++i)
        if (s[i] == '\n') ++line;
      if (i + 1 >= n) throw ParseError{start, "unterminated /* comment"};
      i += 2;
    } else if (c == '#' && line_start) {
      size_t e = s.find('\n', i);
      if (e == std::string::npos) e = n;
      CheckDirective(std::string_view(s.data() + i + 1, e - i - 1), line);
      i = e;
    } else {
      line_start = false;
      tokens.push_back(ReadToken(s, &i, line));
    }
  }
  Token end;
  end.line = line;
  tokens.push_back(end);
  return tokens;
}

// Words that start constructs we do not support, with what to say about them.
bool IsUnsupportedKeyword(const std::string& w) {
  static const std::unordered_set<std::string> kWords = {
      "union", "map", "bitset", "bitmask", "wchar", "wstring", "fixed", "any", "interface",
      "valuetype", "exception", "native", "Object", "ValueBase", "abstract", "local", "custom",
      "eventtype", "component", "home", "porttype", "connector", "attribute", "readonly",
  };
  return kWords.count(w) != 0;
}

class Parser {
 public:
  Parser(std::vector<Token> tokens, SchemaImpl* out) : tokens_(std::move(tokens)), out_(out) {}

  void ParseAll() {
    Definitions(/*in_module=*/false);
  }

 private:
  struct Symbol {
    enum class Kind { kStruct, kEnum, kTypedef, kConst };
    Kind kind;
    int index;       // kStruct: structs; kEnum: enums; kTypedef: nodes
    int line;
    int64_t value;   // kConst
  };

  const Token& Peek(size_t k = 0) const {
    return tokens_[std::min(pos_ + k, tokens_.size() - 1)];
  }
  const Token& Next() {
    const Token& t = Peek();
    if (pos_ < tokens_.size() - 1) ++pos_;
    return t;
  }
  bool PeekIs(const char* text) const {
    const Token& t = Peek();
    return t.type != Token::Type::kEnd && t.type != Token::Type::kLiteral && t.text == text;
  }
  bool Accept(const char* text) {
    if (!PeekIs(text)) return false;
    Next();
    return true;
  }
  static std::string Describe(const Token& t) {
    return t.type == Token::Type::kEnd ? "end of text" : "'" + t.text + "'";
  }
  [[noreturn]] void Fail(const std::string& message) const { throw ParseError{Peek().line, message}; }
  [[noreturn]] static void FailAt(int line, const std::string& message) {
    throw ParseError{line, message};
  }
  [[noreturn]] void Unsupported(const std::string& message) const {
    throw ParseError{Peek().line, message, true};
  }
  [[noreturn]] static void UnsupportedAt(int line, const std::string& message) {
    throw ParseError{line, message, true};
  }
  void Expect(const char* text, const char* context) {
    if (!Accept(text)) {
      Fail(std::string("expected '") + text + "' " + context + ", found " + Describe(Peek()));
    }
  }
  std::string Identifier(const char* what) {
    const Token& t = Peek();
    if (t.type != Token::Type::kIdent) Fail(std::string("expected ") + what + ", found " + Describe(t));
    return Next().text;
  }

  std::string Qualify(const std::string& name) const {
    std::string q;
    for (const std::string& s : scope_) q += s + "::";
    return q + name;
  }

  // Definitions until '}' (in a module) or the end of the text.
  void Definitions(bool in_module) {
    for (;;) {
      Annotations();
      const Token& t = Peek();
      if (t.type == Token::Type::kEnd) {
        if (in_module) Fail("expected '}' closing module '" + scope_.back() + "', found end of text");
        return;
      }
      if (in_module && PeekIs("}")) return;
      if (Accept(";")) continue;  // stray semicolons are harmless
      if (t.type == Token::Type::kIdent) {
        if (t.text == "module") { Next(); Module(); continue; }
        if (t.text == "struct") { Next(); Struct(); continue; }
        if (t.text == "enum") { Next(); Enum(); continue; }
        if (t.text == "typedef") { Next(); Typedef(); continue; }
        if (t.text == "const") { Next(); Const(); continue; }
        if (IsUnsupportedKeyword(t.text)) Unsupported("'" + t.text + "' is not supported");
      }
      Fail("expected a definition (module, struct, enum, typedef, const), found " + Describe(t));
    }
  }

  // Skips annotations, rejecting those that change the layout or that we do not know.
  void Annotations() {
    while (PeekIs("@")) {
      const int line = Peek().line;
      Next();
      const std::string name = Identifier("an annotation name after '@'");
      static const std::unordered_set<std::string> kIgnored = {
          "key", "Key", "topic", "nested", "final", "appendable", "unit", "min", "max", "range",
          "default", "verbatim", "extensibility",
      };
      if (!kIgnored.count(name)) {
        UnsupportedAt(line, "annotation @" + name + " is not supported");
      }
      std::string args;
      if (Accept("(")) {
        int depth = 1;
        while (depth > 0) {
          const Token& t = Next();
          if (t.type == Token::Type::kEnd) FailAt(line, "unterminated arguments of @" + name);
          if (t.type == Token::Type::kPunct && t.text == "(") ++depth;
          if (t.type == Token::Type::kPunct && t.text == ")") --depth;
          if (depth > 0) args += t.text;
        }
      }
      if (name == "extensibility" && args != "FINAL" && args != "APPENDABLE") {
        UnsupportedAt(line, "@extensibility(" + args + ") is not supported (only FINAL and APPENDABLE)");
      }
    }
  }

  // Guards the recursion of Module and TypeSpec against absurdly deep input.
  void Deeper() {
    if (++depth_ > kMaxDepth) Fail("nesting deeper than " + std::to_string(kMaxDepth) + " levels");
  }
  static constexpr int kMaxDepth = 64;

  void Module() {
    Deeper();
    const std::string name = Identifier("a module name");
    Expect("{", "after the module name");
    scope_.push_back(name);
    Definitions(/*in_module=*/true);
    scope_.pop_back();
    Expect("}", "closing the module");
    Expect(";", "after the module's '}'");
    --depth_;
  }

  // Registers `qualified` unless it exists. Returns false if an identical definition already
  // exists (the new one is to be dropped); throws if a different one does.
  bool Declare(const std::string& qualified, Symbol symbol, bool identical_to_existing) {
    auto it = symbols_.find(qualified);
    if (it == symbols_.end()) {
      symbols_.emplace(qualified, symbol);
      return true;
    }
    if (identical_to_existing) return false;
    FailAt(symbol.line, "'" + qualified + "' is already defined (line " +
                            std::to_string(it->second.line) + ") differently");
  }

  const Symbol* Existing(const std::string& qualified, Symbol::Kind kind) const {
    auto it = symbols_.find(qualified);
    return it != symbols_.end() && it->second.kind == kind ? &it->second : nullptr;
  }

  void Struct() {
    const int line = Peek().line;
    const std::string name = Identifier("a struct name");
    StructDef def;
    def.name = Qualify(name);
    def.line = line;
    if (Accept(";")) UnsupportedAt(line, "forward declaration of struct '" + name + "' is not supported");
    if (Accept(":")) {
      const int base_line = Peek().line;
      const std::string base = ScopedName();
      const Symbol* s = Lookup(base);
      if (!s || s->kind != Symbol::Kind::kStruct) {
        FailAt(base_line, "base '" + base + "' of struct '" + name + "' is not a known struct");
      }
      def.members = out_->structs[s->index].members;
    }
    Expect("{", "after the struct name");
    std::unordered_set<std::string> names;
    for (const Member& m : def.members) names.insert(m.name);
    while (!PeekIs("}")) {
      Annotations();
      if (PeekIs("}")) break;
      if (Peek().type == Token::Type::kEnd) Fail("expected '}' closing struct '" + name + "'");
      const int type = TypeSpec();
      do {
        const int member_line = Peek().line;
        Member m;
        m.node = Declarator(type, &m.name);
        if (!names.insert(m.name).second) {
          FailAt(member_line, "struct '" + name + "' has two members named '" + m.name + "'");
        }
        def.members.push_back(std::move(m));
      } while (Accept(","));
      Expect(";", "after a member");
    }
    Expect("}", "closing the struct");
    Expect(";", "after the struct's '}'");
    if (def.members.empty()) UnsupportedAt(line, "struct '" + name + "' has no members (not supported)");
    for (const Member& m : def.members) def.depth = std::max(def.depth, out_->nodes[m.node].depth + 1);
    if (def.depth > kMaxDepth) {
      FailAt(line, "types nested deeper than " + std::to_string(kMaxDepth) + " levels");
    }

    const Symbol* old = Existing(def.name, Symbol::Kind::kStruct);
    const bool same = old && SameMembers(out_->structs[old->index].members, def.members);
    const int index = static_cast<int>(out_->structs.size());
    if (Declare(def.name, Symbol{Symbol::Kind::kStruct, index, line, 0}, same)) {
      out_->struct_index.emplace(def.name, index);
      out_->structs.push_back(std::move(def));
    }
  }

  void Enum() {
    const int line = Peek().line;
    const std::string name = Identifier("an enum name");
    EnumDef def;
    def.name = Qualify(name);
    Expect("{", "after the enum name");
    do {
      Annotations();
      if (PeekIs("}")) break;  // trailing comma
      def.enumerators.push_back(Identifier("an enumerator"));
      if (PeekIs("=")) Unsupported("enumerator values are not supported");
    } while (Accept(","));
    Expect("}", "closing the enum");
    Expect(";", "after the enum's '}'");
    if (def.enumerators.empty()) FailAt(line, "enum '" + name + "' has no enumerators");
    const Symbol* old = Existing(def.name, Symbol::Kind::kEnum);
    const bool same = old && out_->enums[old->index].enumerators == def.enumerators;
    const int index = static_cast<int>(out_->enums.size());
    if (Declare(def.name, Symbol{Symbol::Kind::kEnum, index, line, 0}, same)) {
      out_->enums.push_back(std::move(def));
    }
  }

  void Typedef() {
    const int type = TypeSpec();
    do {
      const int line = Peek().line;
      std::string name;
      const int node = Declarator(type, &name);
      const std::string qualified = Qualify(name);
      const Symbol* old = Existing(qualified, Symbol::Kind::kTypedef);
      const bool same = old && SameNode(old->index, node);
      Declare(qualified, Symbol{Symbol::Kind::kTypedef, node, line, 0}, same);
    } while (Accept(","));
    Expect(";", "after a typedef");
  }

  void Const() {
    const int line = Peek().line;
    const int type = TypeSpec();
    const TypeNode& t = out_->nodes[type];
    if (t.kind != TypeNode::Kind::kPrim || t.prim == Prim::kBool || t.prim == Prim::kChar ||
        t.prim == Prim::kFloat || t.prim == Prim::kDouble) {
      FailAt(line, "only integer constants are supported");
    }
    const std::string name = Identifier("a constant name");
    Expect("=", "after the constant name");
    const bool negative = Accept("-");
    const int64_t value = IntegerLiteral() * (negative ? -1 : 1);
    Expect(";", "after a constant (only a literal value is supported)");
    const std::string qualified = Qualify(name);
    const Symbol* old = Existing(qualified, Symbol::Kind::kConst);
    Declare(qualified, Symbol{Symbol::Kind::kConst, -1, line, value}, old && old->value == value);
  }

  int64_t IntegerLiteral() {
    const Token& t = Peek();
    if (t.type != Token::Type::kNumber) Fail("expected an integer, found " + Describe(t));
    std::string_view text = t.text;
    int base = 10;
    if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X')) {
      base = 16;
      text.remove_prefix(2);
    }
    uint64_t v = 0;
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v, base);
    if (ec != std::errc() || end != text.data() + text.size() ||
        v > static_cast<uint64_t>(std::numeric_limits<int64_t>::max())) {
      Fail("'" + t.text + "' is not a supported integer literal");
    }
    Next();
    return static_cast<int64_t>(v);
  }

  // A positive bound or array size: a literal or the name of an integer constant.
  uint32_t Bound(const char* what) {
    const int line = Peek().line;
    int64_t v;
    if (Peek().type == Token::Type::kIdent || PeekIs("::")) {
      const std::string name = ScopedName();
      const Symbol* s = Lookup(name);
      if (!s || s->kind != Symbol::Kind::kConst) FailAt(line, "'" + name + "' is not an integer constant");
      v = s->value;
    } else {
      v = IntegerLiteral();
    }
    if (v <= 0 || v > std::numeric_limits<uint32_t>::max()) {
      FailAt(line, std::string(what) + " must be between 1 and 4294967295, not " + std::to_string(v));
    }
    return static_cast<uint32_t>(v);
  }

  std::string ScopedName() {
    std::string name;
    if (Accept("::")) name = "::";
    name += Identifier("a type name");
    while (Accept("::")) name += "::" + Identifier("a name after '::'");
    return name;
  }

  // IDL scoping: a relative name is looked up in the current module, then in each enclosing one.
  const Symbol* Lookup(const std::string& name) const {
    if (name.starts_with("::")) {
      auto it = symbols_.find(name.substr(2));
      return it == symbols_.end() ? nullptr : &it->second;
    }
    for (size_t k = scope_.size() + 1; k-- > 0;) {
      std::string q;
      for (size_t j = 0; j < k; ++j) q += scope_[j] + "::";
      auto it = symbols_.find(q + name);
      if (it != symbols_.end()) return &it->second;
    }
    return nullptr;
  }

  int AddNode(TypeNode n) {
    if (n.elem >= 0) n.depth = out_->nodes[n.elem].depth + 1;
    if (n.kind == TypeNode::Kind::kStruct) n.depth = out_->structs[n.def].depth;
    if (n.depth > kMaxDepth) Fail("types nested deeper than " + std::to_string(kMaxDepth) + " levels");
    out_->nodes.push_back(n);
    return static_cast<int>(out_->nodes.size() - 1);
  }
  int PrimNode(Prim p) {
    TypeNode n;
    n.kind = TypeNode::Kind::kPrim;
    n.prim = p;
    return AddNode(n);
  }

  int TypeSpec() {
    const Token& t = Peek();
    const int line = t.line;
    if (t.type != Token::Type::kIdent && !(t.type == Token::Type::kPunct && t.text == "::")) {
      Fail("expected a type, found " + Describe(t));
    }
    const std::string w = t.text;
    if (w == "unsigned") {
      Next();
      if (Accept("short")) return PrimNode(Prim::kUInt16);
      if (Accept("long")) return PrimNode(Accept("long") ? Prim::kUInt64 : Prim::kUInt32);
      Fail("expected 'short' or 'long' after 'unsigned', found " + Describe(Peek()));
    }
    if (w == "long") {
      Next();
      if (Accept("long")) return PrimNode(Prim::kInt64);
      if (PeekIs("double")) UnsupportedAt(line, "'long double' is not supported");
      return PrimNode(Prim::kInt32);
    }
    static const std::unordered_map<std::string, Prim> kPrims = {
        {"boolean", Prim::kBool}, {"octet", Prim::kOctet}, {"char", Prim::kChar},
        {"short", Prim::kInt16}, {"float", Prim::kFloat}, {"double", Prim::kDouble},
        {"int8", Prim::kInt8}, {"uint8", Prim::kUInt8}, {"int16", Prim::kInt16},
        {"uint16", Prim::kUInt16}, {"int32", Prim::kInt32}, {"uint32", Prim::kUInt32},
        {"int64", Prim::kInt64}, {"uint64", Prim::kUInt64},
    };
    if (auto it = kPrims.find(w); it != kPrims.end()) {
      Next();
      return PrimNode(it->second);
    }
    if (w == "string") {
      Next();
      TypeNode n;
      n.kind = TypeNode::Kind::kString;
      if (Accept("<")) {
        n.size = Bound("a string bound");
        Expect(">", "closing the string bound");
      }
      return AddNode(n);
    }
    if (w == "sequence") {
      Next();
      Expect("<", "after 'sequence'");
      Deeper();
      TypeNode n;
      n.kind = TypeNode::Kind::kSequence;
      n.elem = TypeSpec();
      if (Accept(",")) n.size = Bound("a sequence bound");
      Expect(">", "closing the sequence");
      --depth_;
      return AddNode(n);
    }
    if (IsUnsupportedKeyword(w)) Unsupported("'" + w + "' is not supported");
    const std::string name = ScopedName();
    const Symbol* s = Lookup(name);
    if (!s) FailAt(line, "unknown type '" + name + "'");
    switch (s->kind) {
      case Symbol::Kind::kTypedef:
        return s->index;
      case Symbol::Kind::kStruct: {
        TypeNode n;
        n.kind = TypeNode::Kind::kStruct;
        n.def = s->index;
        return AddNode(n);
      }
      case Symbol::Kind::kEnum: {
        TypeNode n;
        n.kind = TypeNode::Kind::kEnum;
        n.def = s->index;
        return AddNode(n);
      }
      case Symbol::Kind::kConst:
        break;
    }
    FailAt(line, "'" + name + "' is a constant, not a type");
  }

  // name [N][M]...: wraps `type` in arrays, outermost first.
  int Declarator(int type, std::string* name) {
    *name = Identifier("a name");
    std::vector<uint32_t> dims;
    while (Accept("[")) {
      dims.push_back(Bound("an array size"));
      Expect("]", "closing the array size");
    }
    int node = type;
    for (size_t k = dims.size(); k-- > 0;) {
      TypeNode n;
      n.kind = TypeNode::Kind::kArray;
      n.size = dims[k];
      n.elem = node;
      node = AddNode(n);
    }
    return node;
  }

  bool SameNode(int a, int b) const {
    if (a == b) return true;
    const TypeNode& x = out_->nodes[a];
    const TypeNode& y = out_->nodes[b];
    if (x.kind != y.kind || x.prim != y.prim || x.size != y.size || x.def != y.def) return false;
    return x.elem < 0 ? y.elem < 0 : (y.elem >= 0 && SameNode(x.elem, y.elem));
  }
  bool SameMembers(const std::vector<Member>& a, const std::vector<Member>& b) const {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i) {
      if (a[i].name != b[i].name || !SameNode(a[i].node, b[i].node)) return false;
    }
    return true;
  }

  std::vector<Token> tokens_;
  size_t pos_ = 0;
  SchemaImpl* out_;
  std::vector<std::string> scope_;
  std::unordered_map<std::string, Symbol> symbols_;
  int depth_ = 0;
};

// Smallest number of bytes one value of `node` takes on the wire (>= 1; structs are never empty).
uint32_t MinWireSize(const SchemaImpl& s, int node) {
  const TypeNode& n = s.nodes[node];
  switch (n.kind) {
    case TypeNode::Kind::kPrim: return PrimSize(n.prim);
    case TypeNode::Kind::kString:
    case TypeNode::Kind::kSequence:
    case TypeNode::Kind::kEnum: return 4;
    case TypeNode::Kind::kArray: {
      const uint64_t v = uint64_t{n.size} * MinWireSize(s, n.elem);
      return static_cast<uint32_t>(std::min<uint64_t>(v, std::numeric_limits<uint32_t>::max()));
    }
    case TypeNode::Kind::kStruct:
      return s.structs[n.def].min_size;
  }
  return 1;
}

// Bounds the ops of one struct: nesting structs inside structs multiplies them. (Nesting depth,
// hence the recursion here and in the decoder, is bounded by the parser.)
constexpr size_t kMaxOps = 1 << 20;

// Appends the ops decoding one value of `node`. Throws past kMaxOps.
void Emit(const SchemaImpl& s, int node, const std::string& name, std::vector<Op>* ops) {
  if (ops->size() >= kMaxOps) throw ParseError{0, ""};
  const TypeNode& n = s.nodes[node];
  Op op;
  op.name = name;
  const size_t at = ops->size();
  switch (n.kind) {
    case TypeNode::Kind::kPrim:
      op.code = OpCode::kPrim;
      op.prim = n.prim;
      ops->push_back(std::move(op));
      return;
    case TypeNode::Kind::kString:
      op.code = OpCode::kString;
      ops->push_back(std::move(op));
      return;
    case TypeNode::Kind::kEnum:
      op.code = OpCode::kEnum;
      op.arg = static_cast<uint32_t>(n.def);
      ops->push_back(std::move(op));
      return;
    case TypeNode::Kind::kStruct:
      op.code = OpCode::kStruct;
      ops->push_back(std::move(op));
      for (const Member& m : s.structs[n.def].members) Emit(s, m.node, m.name, ops);
      break;
    case TypeNode::Kind::kSequence:
      op.code = OpCode::kSequence;
      op.min_elem = MinWireSize(s, n.elem);
      ops->push_back(std::move(op));
      Emit(s, n.elem, "", ops);
      break;
    case TypeNode::Kind::kArray:
      op.code = OpCode::kArray;
      op.arg = n.size;
      op.min_elem = MinWireSize(s, n.elem);
      ops->push_back(std::move(op));
      Emit(s, n.elem, "", ops);
      break;
  }
  (*ops)[at].end = static_cast<uint32_t>(ops->size());
}

}  // namespace
}  // namespace internal

Schema::Schema() : impl_(std::make_shared<internal::SchemaImpl>()) {}

Schema::Schema(std::shared_ptr<const internal::SchemaImpl> impl) : impl_(std::move(impl)) {}

const internal::SchemaImpl* ImplOf(const Schema& schema) { return schema.impl_.get(); }

StatusOr<Schema> Schema::Parse(const std::string& idl_text) {
  auto impl = std::make_shared<internal::SchemaImpl>();
  try {
    internal::Parser parser(internal::Tokenize(idl_text), impl.get());
    parser.ParseAll();
  } catch (const internal::ParseError& e) {
    std::string message = "line " + std::to_string(e.line) + ": " + e.message;
    return e.unsupported ? Status::Unimplemented(std::move(message)) : Status::InvalidArgument(std::move(message));
  }
  for (internal::StructDef& def : impl->structs) {
    uint64_t min_size = 0;
    for (const internal::Member& m : def.members) min_size += internal::MinWireSize(*impl, m.node);
    def.min_size = static_cast<uint32_t>(
        std::min<uint64_t>(min_size, std::numeric_limits<uint32_t>::max()));
    try {
      for (const internal::Member& m : def.members) internal::Emit(*impl, m.node, m.name, &def.ops);
    } catch (const internal::ParseError&) {
      return Status::Unimplemented("line " + std::to_string(def.line) + ": struct '" + def.name +
                                   "' is too large to decode (more than " + std::to_string(internal::kMaxOps) +
                                   " steps once nested structs are expanded)");
    }
  }
  return Schema(std::move(impl));
}

bool Schema::HasType(const std::string& qualified_name) const {
  return impl_->FindStruct(qualified_name) != nullptr;
}

}  // namespace dyad::cdr
