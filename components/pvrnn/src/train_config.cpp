#include "dyad/pvrnn/train_config.hpp"

#include <dyad/join_list.hpp>

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <set>
#include <sstream>

namespace dyad::pvrnn {
namespace {

// Collects every error of a config with its position, at most one per key; one per load.
class Reader {
 public:
  Reader(std::string file, std::set<std::string> overridden)
      : file_(std::move(file)), overridden_(std::move(overridden)) {}

  // "file:line:col: key" (1-based), "--set key" for a value from the command line, or
  // "file: key" where the node has no position (an empty file).
  std::string Where(const YAML::Node& n, const std::string& key) const {
    if (Overridden(key)) return "--set " + key;
    const YAML::Mark m = n.Mark();
    if (m.is_null() || m.line < 0) return file_ + ": " + key;
    return file_ + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1) + ": " + key;
  }
  void Error(const YAML::Node& n, const std::string& key, const std::string& msg) {
    if (!reported_.insert(key).second) return;
    errors_.push_back(Where(n, key) + ": " + msg);
  }
  // Checks that `map` (at `key`, "" for the top level) is a mapping of allowed, distinct keys.
  bool Keys(const YAML::Node& map, const std::string& key, const std::set<std::string>& allowed) {
    if (!map.IsMap()) {
      Error(map, key.empty() ? "(top level)" : key, "must be a mapping");
      return false;
    }
    std::set<std::string> seen;
    for (const auto& kv : map) {
      const std::string k = kv.first.as<std::string>();
      const std::string child = key.empty() ? k : key + "." + k;
      if (!allowed.count(k)) {
        Error(kv.first, child, "unknown key (expected one of: " + JoinList(allowed) + ")");
      } else if (!seen.insert(k).second) {
        Error(kv.first, child, "duplicate key");
      }
    }
    return true;
  }
  template <typename T>
  bool Get(const YAML::Node& parent, const std::string& name, const std::string& key, const char* type, T* out,
           bool required = false) {
    const YAML::Node n = parent[name];
    if (!n) {
      if (required) Error(parent, key, "required key missing");
      return false;
    }
    try {
      *out = n.as<T>();
      return true;
    } catch (const YAML::Exception&) {
      Error(n, key, std::string("must be ") + type + (n.IsScalar() ? ", got " + n.Scalar() : ""));
      return false;
    }
  }
  template <typename T>
  bool Get(const YAML::Node& list, size_t index, const std::string& key, const char* type, T* out) {
    try {
      *out = list[index].template as<T>();
      return true;
    } catch (const YAML::Exception&) {
      Error(list[index], key, std::string("must be ") + type);
      return false;
    }
  }
  // A rule of a config-only field (one no settings struct validates).
  template <typename T>
  void Check(bool ok, const YAML::Node& parent, const std::string& name, const std::string& key, const char* rule,
             const T& value) {
    if (ok) return;
    std::ostringstream s;
    s << rule << ", got " << value;
    const YAML::Node n = parent[name];
    Error(n ? n : parent, key, s.str());
  }
  const std::vector<std::string>& errors() const { return errors_; }

  // A path at `key`: written in the file, relative to the file's folder; given with --set,
  // relative to the working folder. Absolute and empty paths are kept.
  void ResolvePath(const std::string& key, std::string* value) const {
    if (value->empty() || std::filesystem::path(*value).is_absolute()) return;
    std::error_code ec;
    const std::filesystem::path base =
        Overridden(key) ? std::filesystem::current_path(ec) : std::filesystem::absolute(file_, ec).parent_path();
    *value = (base / *value).lexically_normal().string();
  }

 private:
  // True when --set replaced the value at `key`, at a key containing it ("adam" for
  // "adam.lr") or inside it ("adam.lr.x" for "adam.lr").
  bool Overridden(const std::string& key) const {
    auto within = [](const std::string& inner, const std::string& outer) {
      return inner == outer || (inner.size() > outer.size() && inner.rfind(outer, 0) == 0 &&
                                (inner[outer.size()] == '.' || inner[outer.size()] == '['));
    };
    for (const auto& o : overridden_)
      if (within(key, o) || within(o, key)) return true;
    return false;
  }
  std::string file_;
  std::set<std::string> overridden_;
  std::set<std::string> reported_;
  std::vector<std::string> errors_;
};

// The config key of a settings field: the spec's output encoding is `encoding` in the config.
std::string ConfigKey(const std::string& field) {
  return field.rfind("output", 0) == 0 ? "encoding" + field.substr(6) : field;
}

// The node at a config key ("layers[1].d", "encoding.dofs[0]"), or, where the key is absent,
// its deepest present ancestor (for a position).
YAML::Node NodeAt(const YAML::Node& root, const std::string& key) {
  YAML::Node n;
  n.reset(root);
  size_t pos = 0;
  while (pos < key.size()) {
    if (key[pos] == '.') ++pos;
    YAML::Node next;
    if (key[pos] == '[') {
      const size_t close = key.find(']', pos);
      const size_t idx = std::stoul(key.substr(pos + 1, close - pos - 1));
      if (!n.IsSequence() || idx >= n.size()) return n;
      next.reset(static_cast<const YAML::Node&>(n)[idx]);
      pos = close + 1;
    } else {
      const size_t end = std::min(key.find_first_of(".[", pos), key.size());
      const std::string name = key.substr(pos, end - pos);
      if (!n.IsMap() || !static_cast<const YAML::Node&>(n)[name]) return n;
      next.reset(static_cast<const YAML::Node&>(n)[name]);
      pos = end;
    }
    n.reset(next);
  }
  return n;
}

// "layers.1.d" -> "layers[1].d", the spelling used in messages.
std::string MessageKey(const std::string& dotted) {
  std::string out;
  std::stringstream ss(dotted);
  for (std::string p; std::getline(ss, p, '.');) {
    if (!p.empty() && p.find_first_not_of("0123456789") == std::string::npos) out += "[" + p + "]";
    else out += (out.empty() ? "" : ".") + p;
  }
  return out;
}

// "a.b.0.c=value" applied to the YAML tree.
Status ApplyOverride(YAML::Node root, const std::string& spec) {
  const size_t eq = spec.find('=');
  if (eq == std::string::npos || eq == 0) return Status::InvalidArgument("--set " + spec + ": expected key=value");
  const std::string key = spec.substr(0, eq), value = spec.substr(eq + 1);
  std::vector<std::string> parts;
  std::stringstream ss(key);
  for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
  YAML::Node parsed;
  try {
    parsed = YAML::Load(value);
  } catch (const YAML::Exception&) {
    return Status::InvalidArgument("--set " + key + ": value '" + value + "' is not valid YAML");
  }
  // Index into a list, or key of a mapping (created when absent); never into a scalar.
  auto child = [&key](YAML::Node node, const std::string& part, YAML::Node* out) -> Status {
    if (node.IsSequence()) {
      size_t idx = 0;
      if (part.empty() || part.find_first_not_of("0123456789") != std::string::npos)
        return Status::InvalidArgument("--set " + key + ": '" + part + "' is not a list index");
      idx = std::stoul(part);
      if (idx >= node.size()) return Status::InvalidArgument("--set " + key + ": index " + part + " out of range");
      out->reset(node[idx]);
    } else if (node.IsMap() || !node.IsDefined() || node.IsNull()) {
      out->reset(node[part]);
    } else {
      return Status::InvalidArgument("--set " + key + ": cannot set '" + part + "' inside a " +
                                     (node.IsScalar() ? "scalar" : "value"));
    }
    return Status::OK();
  };
  try {
    YAML::Node node = root;
    for (const std::string& part : parts) {
      YAML::Node next;
      if (Status s = child(node, part, &next); !s.ok()) return s;
      node.reset(next);
    }
    node = parsed;
  } catch (const YAML::Exception& e) {
    return Status::InvalidArgument("--set " + key + ": " + e.msg);
  }
  return Status::OK();
}

}  // namespace

namespace {

TrainConfig Read(const YAML::Node& root, Reader& r) {
  TrainConfig c;
  if (!r.Keys(root, "", {"dataset", "loops", "layers", "encoding", "epochs", "adam", "seed", "scalar", "noise", "log_every",
                         "checkpoint_every", "output", "checkpoint", "log_csv"}))
    return c;
  if (r.Get(root, "dataset", "dataset", "a path", &c.dataset, true)) r.ResolvePath("dataset", &c.dataset);
  if (r.Get(root, "loops", "loops", "an integer", &c.loops))
    r.Check(c.loops >= 1 && c.loops <= 100, root, "loops", "loops", "must be in 1..100", c.loops);
  // Types here; value rules come from ModelSpec/AdamOptions::Problems() (one place), below.
  // Entries that cannot be read keep a valid default so that indices stay aligned.
  const YAML::Node layers = root["layers"];
  if (!layers) {
    r.Error(root, "layers", "required key missing");
  } else if (!layers.IsSequence() || layers.size() == 0) {
    r.Error(layers, "layers", "must be a non-empty list of {d, z, tau, w}");
  } else {
    for (size_t k = 0; k < layers.size(); ++k) {
      const YAML::Node l = layers[k];
      const std::string p = "layers[" + std::to_string(k) + "]";
      LayerSpec ls;
      if (r.Keys(l, p, {"d", "z", "tau", "w"})) {
        r.Get(l, "d", p + ".d", "an integer", &ls.d, true);
        r.Get(l, "z", p + ".z", "an integer", &ls.z, true);
        r.Get(l, "tau", p + ".tau", "a number", &ls.tau, true);
        r.Get(l, "w", p + ".w", "a number", &ls.w, true);
      }
      c.spec.layers.push_back(ls);
    }
  }
  c.spec.output.dofs = {{-50, 50}, {-50, 50}};
  if (const YAML::Node e = root["encoding"]; e && r.Keys(e, "encoding", {"dofs", "dsoft", "sigma"})) {
    if (const YAML::Node dofs = e["dofs"]) {
      if (!dofs.IsSequence()) {
        r.Error(dofs, "encoding.dofs", "must be a list of [min, max]");
      } else {
        c.spec.output.dofs.clear();
        for (size_t i = 0; i < dofs.size(); ++i) {
          std::vector<double> range;
          if (r.Get(dofs, i, "encoding.dofs[" + std::to_string(i) + "]", "[min, max]", &range) && range.size() != 2)
            r.Error(dofs[i], "encoding.dofs[" + std::to_string(i) + "]", "must be [min, max]");
          c.spec.output.dofs.push_back(range.size() == 2 ? DofRange{range[0], range[1]} : DofRange{});
        }
      }
    }
    r.Get(e, "dsoft", "encoding.dsoft", "a number", &c.spec.output.dsoft);
    r.Get(e, "sigma", "encoding.sigma", "a number", &c.spec.output.sigma);
  }
  if (r.Get(root, "epochs", "epochs", "an integer", &c.epochs)) r.Check(c.epochs > 0, root, "epochs", "epochs", "must be > 0", c.epochs);
  if (const YAML::Node a = root["adam"]; a && r.Keys(a, "adam", {"lr", "beta1", "beta2", "epsilon"})) {
    r.Get(a, "lr", "adam.lr", "a number", &c.adam.lr);
    r.Get(a, "beta1", "adam.beta1", "a number", &c.adam.beta1);
    r.Get(a, "beta2", "adam.beta2", "a number", &c.adam.beta2);
    r.Get(a, "epsilon", "adam.epsilon", "a number", &c.adam.epsilon);
  }
  r.Get(root, "seed", "seed", "a non-negative integer", &c.seed);
  if (r.Get(root, "scalar", "scalar", "a string", &c.scalar))
    r.Check(c.scalar == "float" || c.scalar == "double", root, "scalar", "scalar", "must be float or double", c.scalar);
  r.Get(root, "noise", "noise", "true or false", &c.noise);
  if (r.Get(root, "log_every", "log_every", "an integer", &c.log_every))
    r.Check(c.log_every > 0, root, "log_every", "log_every", "must be > 0", c.log_every);
  if (r.Get(root, "checkpoint_every", "checkpoint_every", "an integer", &c.checkpoint_every))
    r.Check(c.checkpoint_every >= 0, root, "checkpoint_every", "checkpoint_every", "must be >= 0", c.checkpoint_every);
  if (r.Get(root, "output", "output", "a path", &c.output, true)) r.ResolvePath("output", &c.output);
  if (r.Get(root, "checkpoint", "checkpoint", "a path", &c.checkpoint)) r.ResolvePath("checkpoint", &c.checkpoint);
  if (r.Get(root, "log_csv", "log_csv", "a path", &c.log_csv)) r.ResolvePath("log_csv", &c.log_csv);
  if (c.checkpoint.empty() && !c.output.empty()) c.checkpoint = c.output + ".ckpt";
  if (c.log_csv.empty() && !c.output.empty()) c.log_csv = c.output + ".csv";
  std::vector<FieldProblem> problems = c.spec.Problems();
  for (FieldProblem& p : c.adam.Problems()) problems.push_back(std::move(p));
  for (const FieldProblem& p : problems) {
    const std::string key = ConfigKey(p.field);
    r.Error(NodeAt(root, key), key, p.message);
  }
  return c;
}

}  // namespace

StatusOr<TrainConfig> LoadTrainConfig(const std::string& path, const std::vector<std::string>& overrides) {
  YAML::Node root;
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return Status::InvalidArgument(path + ": is a folder, not a config file");
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    return Status::NotFound(path + ": cannot open");
  } catch (const YAML::Exception& e) {
    if (e.mark.is_null()) return Status::InvalidArgument(path + ": " + e.msg);
    return Status::InvalidArgument(path + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                                   ": " + e.msg);
  }
  std::set<std::string> overridden;
  for (const auto& o : overrides) {
    if (Status s = ApplyOverride(root, o); !s.ok()) return s;
    overridden.insert(MessageKey(o.substr(0, o.find('='))));
  }
  Reader r(path, overridden);
  TrainConfig c;
  try {
    c = Read(root, r);
  } catch (const YAML::Exception& e) {  // e.g. a key that is itself a list: not our format
    return Status::InvalidArgument(path + ": " + e.msg);
  }
  if (!r.errors().empty()) {
    std::string all;
    for (const auto& e : r.errors()) all += (all.empty() ? "" : "\n") + e;
    return Status::InvalidArgument(all);
  }
  return c;
}

}  // namespace dyad::pvrnn
