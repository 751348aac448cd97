#include "dyad/params.hpp"

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace dyad {

const char* ToString(ParamType type) {
  switch (type) {
    case ParamType::kBool: return "bool";
    case ParamType::kInt: return "int";
    case ParamType::kDouble: return "double";
    case ParamType::kString: return "string";
    case ParamType::kDoubleList: return "list of double";
    case ParamType::kStringList: return "list of string";
    case ParamType::kYaml: return "yaml";
  }
  return "?";
}

const ParamValue& Params::Get(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) {
    std::fprintf(stderr, "dyad: component asked for undeclared parameter '%s'\n", name.c_str());
    std::abort();
  }
  return it->second;
}

namespace {
template <class T>
const T& As(const ParamValue& v, const std::string& name) {
  if (const T* p = std::get_if<T>(&v)) return *p;
  std::fprintf(stderr, "dyad: parameter '%s' read with the wrong type\n", name.c_str());
  std::abort();
}
}  // namespace

bool Params::Bool(const std::string& n) const { return As<bool>(Get(n), n); }
int64_t Params::Int(const std::string& n) const { return As<int64_t>(Get(n), n); }
double Params::Double(const std::string& n) const {
  const ParamValue& v = Get(n);
  if (const int64_t* i = std::get_if<int64_t>(&v)) return static_cast<double>(*i);
  return As<double>(v, n);
}
const std::string& Params::String(const std::string& n) const { return As<std::string>(Get(n), n); }
const std::vector<double>& Params::DoubleList(const std::string& n) const { return As<std::vector<double>>(Get(n), n); }
const std::vector<std::string>& Params::StringList(const std::string& n) const {
  return As<std::vector<std::string>>(Get(n), n);
}

std::string ToYamlText(const ParamValue& value) {
  std::ostringstream os;
  std::visit(
      [&](const auto& v) {
        using V = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<V, bool>) os << (v ? "true" : "false");
        else if constexpr (std::is_same_v<V, int64_t> || std::is_same_v<V, double>) os << v;
        else if constexpr (std::is_same_v<V, std::string>) os << '"' << v << '"';
        else {
          os << '[';
          for (size_t i = 0; i < v.size(); ++i) {
            if (i) os << ", ";
            if constexpr (std::is_same_v<V, std::vector<std::string>>) os << '"' << v[i] << '"';
            else os << v[i];
          }
          os << ']';
        }
      },
      value);
  return os.str();
}

}  // namespace dyad
