// The strict YAML reader shared by every format (dyad/strict_yaml.hpp).
#include "dyad/strict_yaml.hpp"

#include "dyad/join_list.hpp"

namespace dyad {
namespace {

// `inner` is `outer` or a key inside it ("adam.lr" or "layers[0]" in "adam" or "layers").
bool Within(const std::string& inner, const std::string& outer) {
  if (inner.size() == outer.size()) return inner == outer;
  return inner.size() > outer.size() && inner.rfind(outer, 0) == 0 &&
         (inner[outer.size()] == '.' || inner[outer.size()] == '[');
}

}  // namespace

MarkLookup StrictYaml::InFile(std::string file, std::map<std::string, std::string> sets) {
  return [file = std::move(file), sets = std::move(sets)](const std::string& key, const YAML::Node& node) {
    for (const auto& [set_key, text] : sets)
      if (Within(key, set_key) || Within(set_key, key)) return SourceMark{"--set " + text, 0, 0};
    return SourceMark::Of(file, node);
  };
}

void StrictYaml::Error(const YAML::Node& node, const std::string& key, const std::string& message) {
  if (reported_.count(key)) return;  // (before Mark: a lookup may cost)
  Error(Mark(node, key), key, message);
}

void StrictYaml::Error(const SourceMark& mark, const std::string& key, const std::string& message) {
  if (!reported_.insert(key).second) return;
  out_->push_back(Diagnostic{mark, key, message});
}

bool StrictYaml::Map(const YAML::Node& node, const std::string& key, const std::set<std::string>& allowed) {
  if (!node.IsMap()) {
    Error(node, key.empty() ? "(top level)" : key, "must be a mapping");
    return false;
  }
  std::set<std::string> seen;
  for (const auto& kv : node) {
    const std::string k = kv.first.Scalar();
    const std::string path = key.empty() ? k : key + "." + k;
    if (!allowed.empty() && !allowed.count(k))
      Error(kv.first, path, "unknown key (expected one of: " + JoinList(allowed) + ")");
    if (!seen.insert(k).second) Error(kv.first, path, "duplicate key");
  }
  return true;
}

bool StrictYaml::String(const YAML::Node& node, const std::string& key, std::string* out) {
  if (!node.IsScalar() || node.Scalar().empty()) {
    Error(node, key, "must be a non-empty string");
    return false;
  }
  *out = node.Scalar();
  return true;
}

}  // namespace dyad
