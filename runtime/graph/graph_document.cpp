// The document a graph file stands for: its `extends:` chain merged, the --sets written in.
#include "graph/graph_document.hpp"
#include "graph/graph_keys.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/depthguard.h>

namespace dyad {
namespace {

constexpr int kMaxChain = 8;  // files in an extends chain, the graph's own included

// One file's text as a mapping; syntax errors at their line.
YAML::Node LoadDocument(const std::string& text, const std::string& path, std::vector<Diagnostic>* out) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::DeepRecursion& e) {  // yaml-cpp says only "bad file"
    out->push_back({SourceMark{path, e.mark.line + 1, e.mark.column + 1}, "",
                    "YAML syntax error: nested too deeply (" + std::to_string(e.depth()) + " levels)"});
    return YAML::Node();
  } catch (const YAML::ParserException& e) {
    out->push_back({SourceMark{path, e.mark.line + 1, e.mark.column + 1}, "", "YAML syntax error: " + e.msg});
    return YAML::Node();
  }
  if (!root.IsMap()) {
    out->push_back({SourceMark{path, 1, 1}, "", "a graph file must be a YAML mapping"});
    return YAML::Node();
  }
  return root;
}

std::string Join(const std::vector<std::string>& parts, size_t from, size_t to) {
  std::string s;
  for (size_t i = from; i < to; ++i) s += (s.empty() ? "" : ".") + parts[i];
  return s;
}

// `origins[key] = from`, dropping what was recorded under key: its subtree was replaced.
void SetOrigin(std::map<std::string, std::string>* origins, const std::string& key, const std::string& from) {
  for (auto it = origins->lower_bound(key + "."); it != origins->end() && it->first.rfind(key + ".", 0) == 0;)
    it = origins->erase(it);
  (*origins)[key] = from;
}

// `over` merged into `base` (both mappings); see the header for the rules. The map is rebuilt in
// the base's order, new keys last, each pair with the key node of the file that wrote it, so marks
// (the key's line too) stay right.
void Merge(YAML::Node base, const YAML::Node& over, const std::string& prefix, const std::string& file,
           GraphDocument* doc, std::vector<Diagnostic>* out) {
  auto key_of = [&](const std::string& k) { return prefix.empty() ? k : prefix + "." + k; };
  std::map<std::string, std::pair<YAML::Node, YAML::Node>> changes;  // key -> the overlay's key and value
  for (const auto& kv : over) {
    const std::string k = kv.first.Scalar();
    if (prefix.empty() && k == "extends") continue;
    if (!changes.emplace(k, std::make_pair(kv.first, kv.second)).second)
      out->push_back({SourceMark::Of(file, kv.first), key_of(k), "duplicate key"});
  }
  YAML::Node merged(YAML::NodeType::Map);
  auto take = [&](const std::string& k, const YAML::Node& base_key, const YAML::Node& base_value) {
    auto [over_key, value] = changes.at(k);
    const std::string key = key_of(k);
    if (value.Tag() == "!reset") {
      SetOrigin(&doc->origins, key, file);
      return;
    }
    if (value.Tag() == "!override") {
      value.SetTag("");
    } else if (base_value.IsMap() && value.IsMap()) {
      Merge(base_value, value, key, file, doc, out);
      merged.force_insert(base_key, base_value);
      return;
    }
    merged.force_insert(over_key, value);
    SetOrigin(&doc->origins, key, file);
  };
  std::set<std::string> in_base;
  for (const auto& kv : base) {
    const std::string k = kv.first.Scalar();
    in_base.insert(k);
    if (changes.count(k)) take(k, kv.first, kv.second);
    else merged.force_insert(kv.first, kv.second);
  }
  for (const auto& kv : over) {
    const std::string k = kv.first.Scalar();
    if (changes.count(k) && !in_base.count(k) && changes.at(k).first.is(kv.first)) take(k, YAML::Node(), YAML::Node());
  }
  base = merged;  // (assigning to a yaml-cpp node overwrites what it refers to: the map in its parent)
}

// The file `extends:` names, relative to the file that names it; "" (reported) when malformed.
std::string ExtendedPath(const YAML::Node& root, const std::string& path, std::vector<Diagnostic>* out) {
  const YAML::Node ext = root["extends"];
  if (!ext.IsScalar() || ext.Scalar().empty()) {
    out->push_back({SourceMark::Of(path, ext), "extends", "must be the path of the graph file this one changes"});
    return "";
  }
  const std::filesystem::path p(ext.Scalar());
  if (p.is_absolute()) return p.lexically_normal().string();
  return (std::filesystem::path(path).parent_path() / p).lexically_normal().string();
}

std::string Canonical(const std::string& path) {
  std::error_code ec;
  const auto c = std::filesystem::weakly_canonical(path, ec);
  return ec ? path : c.string();
}

// The chain of files from `path` (its document `root`) down to the last base, each with its root.
std::vector<std::pair<std::string, YAML::Node>> ReadChain(const std::string& path, YAML::Node root,
                                                         std::vector<Diagnostic>* out) {
  std::vector<std::pair<std::string, YAML::Node>> chain{{path, root}};
  std::vector<std::string> canonical{Canonical(path)};
  while (chain.back().second["extends"]) {
    const auto& [file, doc] = chain.back();
    const YAML::Node ext = doc["extends"];
    const std::string base = ExtendedPath(doc, file, out);
    if (base.empty()) break;
    std::string names;
    for (const auto& [f, _] : chain) names += f + " -> ";
    if (std::find(canonical.begin(), canonical.end(), Canonical(base)) != canonical.end()) {
      out->push_back({SourceMark::Of(file, ext), "extends", "goes round in a circle: " + names + base});
      break;
    }
    if (static_cast<int>(chain.size()) == kMaxChain) {
      out->push_back({SourceMark::Of(file, ext), "extends",
                      "a chain longer than " + std::to_string(kMaxChain) + " files: " + names + base});
      break;
    }
    std::error_code ec;
    std::ifstream in(base);
    if (!in) {
      out->push_back({SourceMark::Of(file, ext), "extends", "cannot open '" + base + "'"});
      break;
    }
    if (!std::filesystem::is_regular_file(base, ec)) {  // a folder; /dev/zero would be read until memory runs out
      out->push_back({SourceMark::Of(file, ext), "extends", "'" + base + "' is not a file"});
      break;
    }
    std::stringstream text;
    text << in.rdbuf();
    YAML::Node base_root = LoadDocument(text.str(), base, out);
    if (!base_root) break;
    chain.emplace_back(base, base_root);
    canonical.push_back(Canonical(base));
  }
  return chain;
}

// Where an override writes: its key path in the document; empty (reported) when it cannot be placed.
std::vector<std::string> SetPath(const std::string& text, const YAML::Node& root, const SourceMark& cli,
                                 std::vector<Diagnostic>* out) {
  const auto eq = text.find('=');
  const std::string keys = eq == std::string::npos ? "" : text.substr(0, eq);
  std::vector<std::string> parts;
  std::stringstream split(keys);
  for (std::string part; std::getline(split, part, '.');) parts.push_back(part);
  const bool empty_part = std::find(parts.begin(), parts.end(), "") != parts.end() || (!keys.empty() && keys.back() == '.');
  auto fail = [&](const std::string& key, const std::string& why) {
    out->push_back({cli, key, why});
    return std::vector<std::string>{};
  };
  if (parts.empty() || empty_part)
    return fail(text, "expected COMPONENT.PARAM=VALUE, COMPONENT.type=TYPE, clock|seed|domain_id|graph=VALUE, "
                      "network.KEY=VALUE or processes.NAME.KEY=VALUE");
  const std::string& head = parts[0];
  if (parts.size() == 1) {
    if (graph_keys::kScalars.count(head)) return parts;
    return fail(text, "expected COMPONENT.PARAM=VALUE, COMPONENT.type=TYPE, clock|seed|domain_id|graph=VALUE, "
                      "network.KEY=VALUE or processes.NAME.KEY=VALUE");
  }
  if (head == "network" || head == "security") return parts;
  if (head == "topics") return parts.size() == 3 ? parts : fail("topics", "expected topics.TOPIC.KEY=VALUE");
  if (head == "processes") {
    if (parts.size() != 3) return fail("processes", "expected processes.NAME.KEY=VALUE");
    const YAML::Node procs = root["processes"];  // (a key that is absent: a node that throws on IsMap)
    if (!procs || !procs.IsMap() || !procs[parts[1]])
      return fail("processes." + parts[1], "no such process in the graph's `processes:`");
    return parts;
  }
  const YAML::Node comps = root["components"];
  if (!comps || !comps.IsMap() || !comps[head]) return fail("components." + head, "no such component in the graph");
  std::vector<std::string> path = {"components", head};
  if (parts.size() == 2 && (graph_keys::kComponentScalars.count(parts[1]) || parts[1] == "params")) {
    path.push_back(parts[1]);
  } else if ((parts[1] == "inputs" || parts[1] == "outputs") && parts.size() == 3) {
    path.insert(path.end(), {parts[1], parts[2]});
  } else {
    const size_t from = parts[1] == "params" && parts.size() > 2 ? 2 : 1;
    path.insert(path.end(), {"params", Join(parts, from, parts.size())});
  }
  return path;
}

// node[path[i]][path[i+1]]... = value, making the maps on the way. Returns path.size() when
// written, else the index of the part that is not a mapping, and *kind says what it is.
size_t WriteAt(YAML::Node node, const std::vector<std::string>& path, size_t i, const YAML::Node& value,
               std::string* kind) {
  if (i + 1 == path.size()) {
    node[path[i]] = value;
    return path.size();
  }
  // (No `YAML::Node n = ...; n = n[...]`: assigning to a yaml-cpp node overwrites what it refers to.)
  if (!node[path[i]] || node[path[i]].IsNull()) node[path[i]] = YAML::Node(YAML::NodeType::Map);
  if (!node[path[i]].IsMap()) {
    *kind = node[path[i]].IsSequence() ? "a list" : "a scalar";
    return i;
  }
  return WriteAt(node[path[i]], path, i + 1, value, kind);
}

}  // namespace

GraphDocument ReadGraphDocument(const std::string& yaml_text, const std::string& path,
                                std::vector<Diagnostic>* diagnostics) {
  GraphDocument doc;
  const YAML::Node root = LoadDocument(yaml_text, path, diagnostics);
  if (!root.IsMap()) return doc;  // (a null node is "defined" to yaml-cpp: `!root` would not stop here)
  const auto chain = ReadChain(path, root, diagnostics);
  doc.root = chain.back().second;
  if (chain.size() > 1) doc.origins[""] = chain.back().first;  // what no overlay changes
  for (size_t i = chain.size() - 1; i-- > 0;) Merge(doc.root, chain[i].second, "", chain[i].first, &doc, diagnostics);
  for (size_t i = 1; i < chain.size(); ++i) doc.bases.push_back(chain[i].first);
  if (doc.root["extends"]) doc.root.remove("extends");
  return doc;
}

void ApplySets(const std::vector<Override>& overrides, GraphDocument* doc, std::vector<Diagnostic>* diagnostics) {
  for (const Override& o : overrides) {
    const SourceMark cli{"--set " + o.text, 0, 0};
    const std::vector<std::string> path = SetPath(o.text, doc->root, cli, diagnostics);
    if (path.empty()) continue;
    const std::string key = Join(path, 0, path.size());
    YAML::Node value;
    try {
      value = YAML::Load(o.text.substr(o.text.find('=') + 1));
    } catch (const YAML::Exception& e) {
      diagnostics->push_back({cli, key, "value is not valid YAML: " + e.msg});
      continue;
    }
    std::string kind;
    if (const size_t at = WriteAt(doc->root, path, 0, value, &kind); at != path.size()) {
      // A list or scalar in the way (the file may be fine there): the set cannot be placed.
      const std::string in = Join(path, 0, at + 1);
      diagnostics->push_back({cli, key, "cannot set '" + path[at + 1] + "' inside " + in + ", which is " + kind +
                                            ": set " + in + " as a whole"});
      continue;
    }
    SetOrigin(&doc->origins, key, cli.file);
    doc->sets.push_back(o.text);
  }
}

}  // namespace dyad
