// dyad/strict_yaml.hpp — reading a YAML format strictly: every problem of a document at once,
// each at the place that wrote it. The graph file and the training config read with it.
//
//   std::vector<Diagnostic> problems;
//   StrictYaml y(StrictYaml::InFile("train.yaml", {{"epochs", "epochs=0"}}), &problems);
//   if (y.Map(root, "", {"epochs", "adam"})) {
//     int epochs = 1;
//     if (y.Get(root, "epochs", "epochs", &epochs, "an integer", /*required=*/true) && epochs < 1)
//       y.Error(root["epochs"], "epochs", "must be >= 1");   // the format's own rules
//     if (const YAML::Node adam = root["adam"]; adam && y.Map(adam, "adam", {"lr"}))
//       y.Get(adam, "lr", "adam.lr", &lr, "a number");
//   }
//
// Contract:
//   - A problem is a Diagnostic (dyad/diagnostic.hpp): the key's path as the format spells it
//     ("adam.lr", "layers[1].d"), a message, and a position: "file:line:col" (1-based) of the
//     node, "file" alone where the node has none (an empty document), or "--set KEY=VALUE" where
//     the command line gave the value.
//   - At most one problem per key: the first one reported stands, later ones at that key are
//     dropped (a wrong type hides the value's rules; an unknown key is not also a duplicate).
//   - Map(node, key, allowed): a mapping ("must be a mapping"; the top level, key "", is named
//     "(top level)") whose keys are all in `allowed` ("unknown key (expected one of: a, b)";
//     an empty `allowed` takes any key), each written once ("duplicate key"). False when `node`
//     is not a mapping; its keys' problems do not make it false.
//   - String(node, key, &s): a non-empty scalar ("must be a non-empty string").
//   - Get(node, key, &x, what): the node converted to x's type by yaml-cpp, or "must be <what>,
//     got '<value>'" (the value shown when it is a scalar).
//   - Get(parent, name, key, &x, what, required): the same for parent[name] when present; when
//     absent false, and if `required` "required key missing" at the parent.
//   - A getter that finds a problem returns false and leaves its output as it was, so rules on
//     the value run only on what was read.
//   - Positions come from a MarkLookup(key, node), the caller's: InFile(file, sets) for one
//     file edited by --set; the graph passes Graph::MarkOf, which names the file of its
//     `extends:` chain (or the --set) that wrote the key.
//
// Not thread-safe: one StrictYaml per document, used on one thread.
#pragma once

#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "dyad/diagnostic.hpp"

namespace dyad {

// Where the value at `key` (the node `node`) was written.
using MarkLookup = std::function<SourceMark(const std::string& key, const YAML::Node& node)>;

class StrictYaml {
 public:
  // Problems are appended to *out, which must outlive this reader.
  StrictYaml(MarkLookup mark, std::vector<Diagnostic>* out) : mark_(std::move(mark)), out_(out) {}

  // Positions in `file`, except for the keys `sets` maps to the --set text ("adam.lr" ->
  // "adam.lr=0.1") that gave their value: those keys, the keys inside them ("adam.lr" for a
  // set "adam") and the keys holding them ("adam" for a set "adam.lr") are at "--set TEXT".
  static MarkLookup InFile(std::string file, std::map<std::string, std::string> sets);

  SourceMark Mark(const YAML::Node& node, const std::string& key) const { return mark_(key, node); }
  void Error(const YAML::Node& node, const std::string& key, const std::string& message);
  void Error(const SourceMark& mark, const std::string& key, const std::string& message);

  bool Map(const YAML::Node& node, const std::string& key, const std::set<std::string>& allowed);
  bool String(const YAML::Node& node, const std::string& key, std::string* out);

  template <class T>
  bool Get(const YAML::Node& node, const std::string& key, T* out, const std::string& what) {
    try {
      *out = node.as<T>();
      return true;
    } catch (const YAML::Exception&) {
    }
    Error(node, key, "must be " + what + (node.IsScalar() ? ", got '" + node.Scalar() + "'" : ""));
    return false;
  }

  template <class T>
  bool Get(const YAML::Node& parent, const std::string& name, const std::string& key, T* out,
           const std::string& what, bool required = false) {
    const YAML::Node node = parent[name];
    if (node) return Get(node, key, out, what);
    if (required) Error(parent, key, "required key missing");
    return false;
  }

 private:
  MarkLookup mark_;
  std::vector<Diagnostic>* out_;
  std::set<std::string> reported_;  // the keys with a problem
};

}  // namespace dyad
