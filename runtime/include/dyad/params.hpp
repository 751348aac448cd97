// dyad/params.hpp — a component's declared parameters and their validated values.
//
// A component declares each parameter once, in its Describe(): name, type, default (or
// required), unit, valid range and a one-line description. That one declaration serves the
// validator (`dyad validate`), the listing (`dyad types`) and the component itself:
//
//   spec.Param("gain", 0.9).Range(0.0, 1.0).Doc("weight of the human in the blend");
//   spec.RequiredParam("model", ParamType::kString).Path().Doc("model file");
//   ...
//   double g = ctx.params().Double("gain");   // in Configure(): already validated
//
// Paths: a kString or kStringList parameter marked Path() names files or folders (Path() on any
// other type is refused when the plugin is loaded). A relative
// value written in a graph file is resolved against that file's folder (so a graph runs the same
// from any working folder); a relative value given with `--set` on the command line, against the
// working folder (as a shell user expects); a default, as it is (the component's own choice).
// The component always receives the resolved path; empty values stay empty.
//
// Secrets: a kString parameter marked Secret() (a token, a password) is the component's alone:
// the graph text components receive (Context::graph_yaml(), which recorders keep with every
// recording) has each secret's value replaced by "<redacted>", and dyad prints it nowhere.
// (Secret() on any other type is refused when the plugin is loaded.)
//
// Live parameters: a parameter marked Live() may be changed while the graph runs (`dyad param
// set`, the experimenter's page, a param_script; docs/runtime.md "Live parameters"). The new value
// is validated against the same declaration (type, range, choices) and replaces the old one at a
// step boundary of the component: between two of its Step() calls, on its step thread, so a
// component that reads it from ctx.params() in Step() (a map lookup) sees each change at its next
// step and never mid-step. A value read once in Configure() does not change: mark Live() only what
// Step() reads. A live path given relative resolves against the graph file's folder; what it names
// is typically loaded off the step thread (Context::PrepareLiveParam). Secrets and kYaml values
// cannot be live (refused when the plugin is loaded).
//
// Values reach the component only after validation, so getters never fail on user input; asking
// for an undeclared name or the wrong type is a programming error and aborts with a message.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace dyad {

enum class ParamType {
  kBool,
  kInt,        // 64-bit signed
  kDouble,
  kString,
  kDoubleList, // YAML sequence of numbers
  kStringList, // YAML sequence of strings
  kYaml,       // any YAML; the component parses it (kept as YAML text)
};

const char* ToString(ParamType type);

using ParamValue = std::variant<bool, int64_t, double, std::string, std::vector<double>, std::vector<std::string>>;

struct ParamSpec {
  std::string name;
  ParamType type = ParamType::kDouble;
  std::optional<ParamValue> default_value;  // none: the graph must set it
  std::optional<double> min;                 // inclusive; numbers (and each list element)
  std::optional<double> max;                 // inclusive
  std::vector<std::string> choices;          // kString: allowed values, empty = any
  std::string unit;
  std::string doc;
  bool path = false;                         // a file or folder (see the file comment)
  bool secret = false;                       // redacted from the graph text (see the file comment)
  bool live = false;                         // may change while the component runs (see the file comment)

  // Builder-style setters used in Describe().
  ParamSpec& Range(double lo, double hi) { min = lo; max = hi; return *this; }
  ParamSpec& Min(double lo) { min = lo; return *this; }
  ParamSpec& Max(double hi) { max = hi; return *this; }
  ParamSpec& OneOf(std::vector<std::string> values) { choices = std::move(values); return *this; }
  ParamSpec& Unit(std::string u) { unit = std::move(u); return *this; }
  ParamSpec& Doc(std::string d) { doc = std::move(d); return *this; }
  ParamSpec& Path() { path = true; return *this; }
  ParamSpec& Secret() { secret = true; return *this; }
  ParamSpec& Live() { live = true; return *this; }
};

// Validated values of one component instance, defaults filled in.
class Params {
 public:
  Params() = default;
  explicit Params(std::map<std::string, ParamValue> values) : values_(std::move(values)) {}

  bool Bool(const std::string& name) const;
  int64_t Int(const std::string& name) const;
  double Double(const std::string& name) const;  // also accepts an int-typed value
  const std::string& String(const std::string& name) const;  // kString and kYaml
  const std::vector<double>& DoubleList(const std::string& name) const;
  const std::vector<std::string>& StringList(const std::string& name) const;
  bool Has(const std::string& name) const { return values_.count(name) != 0; }
  // The runtime's, for a live parameter's new (validated) value; components only read.
  void Set(const std::string& name, ParamValue value) { values_[name] = std::move(value); }
  const std::map<std::string, ParamValue>& values() const { return values_; }

 private:
  const ParamValue& Get(const std::string& name) const;
  std::map<std::string, ParamValue> values_;
};

// "0.9", "true", "[1, 2]", "\"text\"": a value as YAML flow text.
std::string ToYamlText(const ParamValue& value);

}  // namespace dyad
