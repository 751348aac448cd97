#include "dyad/pvrnn/train_config.hpp"

#include <dyad/strict_yaml.hpp>

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <map>
#include <sstream>
#include <type_traits>

namespace dyad::pvrnn {
namespace {

// A rule of a config-only field (one no settings struct validates), at `key` of the top level.
template <typename T>
void Check(StrictYaml& r, bool ok, const YAML::Node& root, const std::string& key, const char* rule, const T& value) {
  if (ok) return;
  std::ostringstream s;
  s << rule << ", got ";
  if constexpr (std::is_convertible_v<T, std::string>) s << "'" << value << "'";  // the graph's wording
  else s << value;
  const YAML::Node n = root[key];
  r.Error(n ? n : root, key, s.str());
}

// A path at top-level `key`: written in the file, relative to the file's folder; given with
// --set, relative to the working folder. Absolute and empty paths are kept.
void ReadPath(StrictYaml& r, const std::string& file, const YAML::Node& root, const std::string& key,
              std::string* value, bool required = false) {
  if (!r.Get(root, key, key, value, "a path", required)) return;
  if (value->empty() || std::filesystem::path(*value).is_absolute()) return;
  std::error_code ec;
  const std::filesystem::path base = r.Mark(root[key], key).FromCommandLine()
                                         ? std::filesystem::current_path(ec)
                                         : std::filesystem::absolute(file, ec).parent_path();
  *value = (base / *value).lexically_normal().string();
}

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
      if (part.size() > 9) return Status::InvalidArgument("--set " + key + ": index " + part + " out of range");  // (stoul throws past 2^64)
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

// Types here; value rules come from ModelSpec::Problems() (one place), in Read.
// Entries that cannot be read keep a valid default so that indices stay aligned.
void ReadLayers(StrictYaml& r, const YAML::Node& root, ModelSpec* spec) {
  const YAML::Node layers = root["layers"];
  if (!layers) {
    r.Error(root, "layers", "required key missing");
    return;
  }
  if (!layers.IsSequence() || layers.size() == 0) {
    r.Error(layers, "layers", "must be a non-empty list of {d, z, tau, w}");
    return;
  }
  for (size_t k = 0; k < layers.size(); ++k) {
    const YAML::Node l = layers[k];
    const std::string p = "layers[" + std::to_string(k) + "]";
    LayerSpec ls;
    if (r.Map(l, p, {"d", "z", "tau", "w"})) {
      r.Get(l, "d", p + ".d", &ls.d, "an integer", true);
      r.Get(l, "z", p + ".z", &ls.z, "an integer", true);
      r.Get(l, "tau", p + ".tau", &ls.tau, "a number", true);
      r.Get(l, "w", p + ".w", &ls.w, "a number", true);
    }
    spec->layers.push_back(ls);
  }
}

void ReadEncoding(StrictYaml& r, const YAML::Node& root, OutputEncoding* output) {
  output->dofs = {{-50, 50}, {-50, 50}};
  const YAML::Node e = root["encoding"];
  if (!e || !r.Map(e, "encoding", {"dofs", "dsoft", "sigma"})) return;
  if (const YAML::Node dofs = e["dofs"]) {
    if (!dofs.IsSequence()) {
      r.Error(dofs, "encoding.dofs", "must be a list of [min, max]");
    } else {
      output->dofs.clear();
      for (size_t i = 0; i < dofs.size(); ++i) {
        const std::string key = "encoding.dofs[" + std::to_string(i) + "]";
        std::vector<double> range;
        if (r.Get(dofs[i], key, &range, "[min, max]") && range.size() != 2) r.Error(dofs[i], key, "must be [min, max]");
        output->dofs.push_back(range.size() == 2 ? DofRange{range[0], range[1]} : DofRange{});
      }
    }
  }
  r.Get(e, "dsoft", "encoding.dsoft", &output->dsoft, "a number");
  r.Get(e, "sigma", "encoding.sigma", &output->sigma, "a number");
}

void ReadAdam(StrictYaml& r, const YAML::Node& root, AdamOptions* adam) {
  const YAML::Node a = root["adam"];
  if (!a || !r.Map(a, "adam", {"lr", "beta1", "beta2", "epsilon"})) return;
  r.Get(a, "lr", "adam.lr", &adam->lr, "a number");
  r.Get(a, "beta1", "adam.beta1", &adam->beta1, "a number");
  r.Get(a, "beta2", "adam.beta2", &adam->beta2, "a number");
  r.Get(a, "epsilon", "adam.epsilon", &adam->epsilon, "a number");
}

TrainConfig Read(StrictYaml& r, const std::string& file, const YAML::Node& root) {
  TrainConfig c;
  if (!r.Map(root, "",
             {"dataset", "loops", "layers", "encoding", "epochs", "adam", "seed", "scalar", "noise", "prior", "threads",
              "log_every", "checkpoint_every", "output", "checkpoint", "log_csv"}))
    return c;
  ReadPath(r, file, root, "dataset", &c.dataset, true);
  if (r.Get(root, "loops", "loops", &c.loops, "an integer"))
    Check(r, c.loops >= 1 && c.loops <= 100, root, "loops", "must be in 1..100", c.loops);
  ReadLayers(r, root, &c.spec);
  ReadEncoding(r, root, &c.spec.output);
  if (r.Get(root, "epochs", "epochs", &c.epochs, "an integer"))
    Check(r, c.epochs > 0, root, "epochs", "must be > 0", c.epochs);
  ReadAdam(r, root, &c.adam);
  r.Get(root, "seed", "seed", &c.seed, "a non-negative integer");
  if (r.Get(root, "scalar", "scalar", &c.scalar, "a string"))
    Check(r, c.scalar == "float" || c.scalar == "double", root, "scalar", "must be float or double", c.scalar);
  r.Get(root, "noise", "noise", &c.noise, "true or false");
  if (r.Get(root, "prior", "prior", &c.prior, "a string")) {
    Check(r, c.prior == "dyad" || c.prior == "nrl", root, "prior", "must be dyad or nrl", c.prior);
    if (c.prior == "nrl") {
      Check(r, c.scalar == "float", root, "scalar", "must be float with prior: nrl (NRL trains in float)", c.scalar);
      const YAML::Node adam = static_cast<const YAML::Node&>(root)["adam"];
      const bool epsilon_given = adam && adam.IsMap() && static_cast<const YAML::Node&>(adam)["epsilon"];
      if (!epsilon_given) c.adam.epsilon = 1.0e-20;  // NRL's NON_ZERO
    }
  }
  if (r.Get(root, "threads", "threads", &c.threads, "an integer"))
    Check(r, c.threads >= 0 && c.threads <= 256, root, "threads", "must be in 0..256", c.threads);
  if (r.Get(root, "log_every", "log_every", &c.log_every, "an integer"))
    Check(r, c.log_every > 0, root, "log_every", "must be > 0", c.log_every);
  if (r.Get(root, "checkpoint_every", "checkpoint_every", &c.checkpoint_every, "an integer"))
    Check(r, c.checkpoint_every >= 0, root, "checkpoint_every", "must be >= 0", c.checkpoint_every);
  ReadPath(r, file, root, "output", &c.output, true);
  ReadPath(r, file, root, "checkpoint", &c.checkpoint);
  ReadPath(r, file, root, "log_csv", &c.log_csv);
  if (c.checkpoint.empty() && !c.output.empty()) c.checkpoint = c.output + ".ckpt";
  if (c.log_csv.empty() && !c.output.empty()) c.log_csv = c.output + ".csv";
  // The settings' value rules, each at the config key of its field.
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
  std::map<std::string, std::string> sets;  // key as messages spell it -> the --set text
  for (const auto& o : overrides) {
    if (Status s = ApplyOverride(root, o); !s.ok()) return Status::InvalidArgument(s.message() + " (in " + path + ")");
    sets[MessageKey(o.substr(0, o.find('=')))] = o;
  }
  std::vector<Diagnostic> problems;
  StrictYaml r(StrictYaml::InFile(path, sets), &problems);
  TrainConfig c;
  try {
    c = Read(r, path, root);
  } catch (const YAML::Exception& e) {  // e.g. a key that is itself a list: not our format
    return Status::InvalidArgument(path + ": " + e.msg);
  }
  if (!problems.empty()) {
    std::string all;
    for (const Diagnostic& d : problems) all += (all.empty() ? "" : "\n") + d.ToString();
    return Status::InvalidArgument(all);
  }
  return c;
}

}  // namespace dyad::pvrnn
