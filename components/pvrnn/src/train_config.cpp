#include "dyad/pvrnn/train_config.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <set>
#include <sstream>

namespace dyad::pvrnn {
namespace {

// Collects every error of a config with its position; one instance per load.
class Reader {
 public:
  Reader(std::string file, std::set<std::string> overridden)
      : file_(std::move(file)), overridden_(std::move(overridden)) {}

  std::string Where(const YAML::Node& n, const std::string& key) const {
    const YAML::Mark m = n.Mark();
    // A value from --set has no position in the file.
    if (m.line < 0 || overridden_.count(key)) return "--set " + key;
    return file_ + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1) + ": " + key;
  }
  void Error(const YAML::Node& n, const std::string& key, const std::string& msg) {
    errors_.push_back(Where(n, key) + ": " + msg);
  }
  void Keys(const YAML::Node& map, const std::string& prefix, const std::set<std::string>& allowed) {
    if (!map.IsMap()) {
      Error(map, prefix.empty() ? "(top level)" : prefix, "must be a mapping");
      return;
    }
    for (const auto& kv : map) {
      const std::string k = kv.first.as<std::string>();
      if (!allowed.count(k)) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        Error(kv.first, prefix + k, "unknown key (allowed: " + list + ")");
      }
    }
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
      Error(n, key, std::string("must be ") + type);
      return false;
    }
  }
  void Check(bool ok, const YAML::Node& parent, const std::string& name, const std::string& key, const std::string& msg) {
    if (ok) return;
    const YAML::Node n = parent[name];
    std::ostringstream s;
    if (n && n.IsScalar()) s << "= " << n.Scalar() << ": ";
    s << msg;
    Error(n ? n : parent, key, s.str());
  }
  const std::vector<std::string>& errors() const { return errors_; }

 private:
  std::string file_;
  std::set<std::string> overridden_;
  std::vector<std::string> errors_;
};

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
  YAML::Node node = root;
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    const std::string& p = parts[i];
    YAML::Node next;
    if (node.IsSequence()) {
      size_t idx = 0;
      try { idx = std::stoul(p); } catch (const std::exception&) { return Status::InvalidArgument("--set " + key + ": '" + p + "' is not a list index"); }
      if (idx >= node.size()) return Status::InvalidArgument("--set " + key + ": index " + p + " out of range");
      next = node[idx];
    } else {
      next = node[p];
    }
    node.reset(next);
  }
  YAML::Node parsed;
  try { parsed = YAML::Load(value); } catch (const YAML::Exception& e) {
    return Status::InvalidArgument("--set " + key + ": value '" + value + "' is not valid YAML");
  }
  if (node.IsSequence()) {
    size_t idx = 0;
    try { idx = std::stoul(parts.back()); } catch (const std::exception&) { return Status::InvalidArgument("--set " + key + ": not a list index"); }
    if (idx >= node.size()) return Status::InvalidArgument("--set " + key + ": index out of range");
    node[idx] = parsed;
  } else {
    node[parts.back()] = parsed;
  }
  return Status::OK();
}

}  // namespace

StatusOr<TrainConfig> LoadTrainConfig(const std::string& path, const std::vector<std::string>& overrides) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    return Status::NotFound(path + ": cannot open");
  } catch (const YAML::ParserException& e) {
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
  r.Keys(root, "", {"dataset", "layers", "encoding", "epochs", "adam", "seed", "scalar", "noise", "log_every",
                    "checkpoint_every", "output", "checkpoint", "log_csv"});
  if (!root.IsMap()) return Status::InvalidArgument(r.errors().front());
  if (r.Get(root, "dataset", "dataset", "a path", &c.dataset, true)) {
    std::filesystem::path p(c.dataset);
    if (p.is_relative()) p = std::filesystem::path(path).parent_path() / p;
    c.dataset = p.lexically_normal().string();
  }
  const YAML::Node layers = root["layers"];
  if (!layers) {
    r.Error(root, "layers", "required key missing");
  } else if (!layers.IsSequence() || layers.size() == 0) {
    r.Error(layers, "layers", "must be a non-empty list of {d, z, tau, w}");
  } else {
    for (size_t k = 0; k < layers.size(); ++k) {
      const YAML::Node l = layers[k];
      const std::string p = "layers[" + std::to_string(k) + "].";
      r.Keys(l, p, {"d", "z", "tau", "w"});
      if (!l.IsMap()) continue;
      LayerSpec ls;
      if (r.Get(l, "d", p + "d", "an integer", &ls.d, true)) r.Check(ls.d > 0, l, "d", p + "d", "must be > 0");
      if (r.Get(l, "z", p + "z", "an integer", &ls.z, true)) r.Check(ls.z > 0, l, "z", p + "z", "must be > 0");
      if (r.Get(l, "tau", p + "tau", "a number", &ls.tau, true)) r.Check(ls.tau >= 1, l, "tau", p + "tau", "must be >= 1");
      if (r.Get(l, "w", p + "w", "a number", &ls.w, true)) r.Check(ls.w >= 0, l, "w", p + "w", "must be >= 0");
      c.spec.layers.push_back(ls);
    }
  }
  c.spec.output.dofs = {{-50, 50}, {-50, 50}};
  if (const YAML::Node e = root["encoding"]) {
    r.Keys(e, "encoding.", {"dofs", "dsoft", "sigma"});
    if (e.IsMap()) {
      std::vector<std::vector<double>> dofs;
      if (r.Get(e, "dofs", "encoding.dofs", "a list of [min, max]", &dofs)) {
        c.spec.output.dofs.clear();
        for (const auto& d : dofs) {
          const bool ok = d.size() == 2 && d[1] > d[0];
          r.Check(ok, e, "dofs", "encoding.dofs", "each entry must be [min, max] with max > min");
          if (ok) c.spec.output.dofs.push_back({d[0], d[1]});
        }
        r.Check(!dofs.empty(), e, "dofs", "encoding.dofs", "must list at least one DOF");
      }
      if (r.Get(e, "dsoft", "encoding.dsoft", "a number", &c.spec.output.dsoft))
        r.Check(c.spec.output.dsoft > 0, e, "dsoft", "encoding.dsoft", "must be > 0");
      if (r.Get(e, "sigma", "encoding.sigma", "a number", &c.spec.output.sigma))
        r.Check(c.spec.output.sigma > 0, e, "sigma", "encoding.sigma", "must be > 0");
    }
  }
  if (r.Get(root, "epochs", "epochs", "an integer", &c.epochs)) r.Check(c.epochs > 0, root, "epochs", "epochs", "must be > 0");
  if (const YAML::Node a = root["adam"]) {
    r.Keys(a, "adam.", {"lr", "beta1", "beta2", "epsilon"});
    if (a.IsMap()) {
      if (r.Get(a, "lr", "adam.lr", "a number", &c.adam.lr)) r.Check(c.adam.lr > 0, a, "lr", "adam.lr", "must be > 0");
      if (r.Get(a, "beta1", "adam.beta1", "a number", &c.adam.beta1))
        r.Check(c.adam.beta1 >= 0 && c.adam.beta1 < 1, a, "beta1", "adam.beta1", "must be in [0, 1)");
      if (r.Get(a, "beta2", "adam.beta2", "a number", &c.adam.beta2))
        r.Check(c.adam.beta2 >= 0 && c.adam.beta2 < 1, a, "beta2", "adam.beta2", "must be in [0, 1)");
      if (r.Get(a, "epsilon", "adam.epsilon", "a number", &c.adam.epsilon))
        r.Check(c.adam.epsilon > 0, a, "epsilon", "adam.epsilon", "must be > 0");
    }
  }
  r.Get(root, "seed", "seed", "a non-negative integer", &c.seed);
  if (r.Get(root, "scalar", "scalar", "a string", &c.scalar))
    r.Check(c.scalar == "float" || c.scalar == "double", root, "scalar", "scalar", "must be float or double");
  r.Get(root, "noise", "noise", "true or false", &c.noise);
  if (r.Get(root, "log_every", "log_every", "an integer", &c.log_every))
    r.Check(c.log_every > 0, root, "log_every", "log_every", "must be > 0");
  if (r.Get(root, "checkpoint_every", "checkpoint_every", "an integer", &c.checkpoint_every))
    r.Check(c.checkpoint_every >= 0, root, "checkpoint_every", "checkpoint_every", "must be >= 0");
  r.Get(root, "output", "output", "a path", &c.output, true);
  r.Get(root, "checkpoint", "checkpoint", "a path", &c.checkpoint);
  r.Get(root, "log_csv", "log_csv", "a path", &c.log_csv);
  if (c.checkpoint.empty() && !c.output.empty()) c.checkpoint = c.output + ".ckpt";
  if (c.log_csv.empty() && !c.output.empty()) c.log_csv = c.output + ".csv";
  if (!r.errors().empty()) {
    std::string all;
    for (const auto& e : r.errors()) all += (all.empty() ? "" : "\n") + e;
    return Status::InvalidArgument(all);
  }
  if (Status s = c.spec.Validate(); !s.ok()) return Status::InvalidArgument(path + ": " + s.message());
  return c;
}

}  // namespace dyad::pvrnn
