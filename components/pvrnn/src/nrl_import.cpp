#include "dyad/pvrnn/nrl_import.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "nrl_text.hpp"

namespace dyad::pvrnn {
namespace fs = std::filesystem;

namespace {

using internal::Trim;

// A text file of NRL matrices: one comma-separated line per matrix.
class NrlMatrixFile {
 public:
  static StatusOr<NrlMatrixFile> Open(const std::string& path) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) return Status::InvalidArgument(path + ": is a folder, not a file");
    std::ifstream in(path);
    if (!in) return Status::NotFound(path + ": cannot open");
    NrlMatrixFile f;
    f.path_ = path;
    f.name_ = fs::path(path).filename().string();
    std::string line;
    while (std::getline(in, line)) f.lines_.push_back(line);
    return f;
  }
  // Reads the next line as a rows x cols column-major matrix.
  Status Next(int rows, int cols, const std::string& what, Eigen::MatrixXd* out) {
    const std::string where = name_ + ":" + std::to_string(next_ + 1);
    if (next_ >= lines_.size())
      return Status::DataLoss(where + ": missing line for " + what + " (file has " + std::to_string(lines_.size()) + " lines)");
    const std::string& line = lines_[next_++];
    if (std::string bad; !internal::ParseNumberList(line, &values_, &bad))
      return Status::DataLoss(where + ": '" + bad + "' is not a finite number (" + what + ")");
    if (values_.size() != static_cast<size_t>(rows) * cols)
      return Status::DataLoss(where + ": expected " + std::to_string(rows * cols) + " values (" + std::to_string(rows) +
                              " x " + std::to_string(cols) + ": " + what + "), found " + std::to_string(values_.size()));
    *out = Eigen::Map<const Eigen::MatrixXd>(values_.data(), rows, cols);
    return Status::OK();
  }
  size_t size() const { return lines_.size(); }
  const std::string& name() const { return name_; }

 private:
  std::string path_, name_;
  std::vector<std::string> lines_;
  std::vector<double> values_;
  size_t next_ = 0;
};

StatusOr<std::vector<double>> Numbers(const std::string& file, const std::string& key, const std::string& value) {
  std::vector<double> out;
  if (!internal::ParseNumberList(value, &out))
    return Status::DataLoss(file + ": " + key + " = '" + value + "': not a comma-separated list of finite numbers");
  return out;
}

// What the properties file says: the network's shape, and the epochs trained (0 if not said).
struct NrlProperties {
  ModelSpec spec;
  int64_t epochs = 0;
};

// Reads NRL's properties file `pf` (d, z, t, w per layer, activejoints, dsoft, sigma, epochs);
// errors name the file and the property.
StatusOr<NrlProperties> ReadProperties(const std::string& pf) {
  auto kv = ReadKeyValueFile(pf);
  if (!kv.ok()) return kv.status();
  std::map<std::string, std::vector<double>> num;
  std::map<std::string, std::string> text;
  for (const auto& [k, v] : kv.value()) {
    text[k] = v;
    if (k == "d" || k == "z" || k == "t" || k == "w" || k == "dsoft" || k == "sigma" || k == "activejoints" ||
        k == "epochs") {
      auto n = Numbers(pf, k, v);
      if (!n.ok()) return n.status();
      num[k] = n.value();
    }
  }
  for (const char* key : {"d", "z", "t", "w", "activejoints"})
    if (!num.count(key)) return Status::DataLoss(pf + ": property '" + key + "' missing");
  if (text.count("network") && text["network"] != "pvrnn")
    return Status::Unimplemented(pf + ": network=" + text["network"] + ", only pvrnn can be imported" +
                                 (text["network"] == "pvrnnbeta"
                                      ? " (NRL's PV-RNN Beta: top-down only, other prior and KL at the first step; docs/pvrnn.md)"
                                      : ""));
  if (text.count("robot") && text["robot"] != "cartesian")
    return Status::Unimplemented(pf + ": robot=" + text["robot"] + ", only the cartesian robot (joints -50..50) is supported");
  const size_t K = num["d"].size();
  if (num["z"].size() != K || num["t"].size() != K || num["w"].size() != K)
    return Status::DataLoss(pf + ": d, z, t and w must list the same number of layers");
  for (const char* key : {"d", "z"})
    for (double v : num[key])
      if (!(v >= 1 && v <= 100000 && v == std::floor(v)))
        return Status::DataLoss(pf + ": " + key + " = '" + text[key] + "': each entry must be a whole number in 1..100000");
  ModelSpec spec;
  for (size_t k = 0; k < K; ++k)
    spec.layers.push_back({static_cast<int>(num["d"][k]), static_cast<int>(num["z"][k]), num["t"][k], num["w"][k]});
  for (double a : num["activejoints"])
    if (a == 1) spec.output.dofs.push_back({-50, 50});
  spec.output.dsoft = num.count("dsoft") ? num["dsoft"][0] : 10;
  spec.output.sigma = num.count("sigma") ? num["sigma"][0] : 0.2;
  if (Status s = spec.Validate(); !s.ok()) return Status::DataLoss(pf + ": " + s.message());
  return NrlProperties{spec, num.count("epochs") ? static_cast<int64_t>(num["epochs"][0]) : 0};
}

// Reads the weights, biases and adaptive variables (A) of every layer and output of `dir` into
// *m, whose weights and A are already shaped by `layout`; errors name the file and the matrix.
Status ReadWeights(const fs::path& dir, const NetworkLayout& layout, Model* m) {
  const ModelSpec& spec = m->spec;
  const size_t K = spec.layers.size();
  const int prims = m->adaptive.sequences(), steps = m->adaptive.steps();
  Eigen::MatrixXd buf;
  auto group = [&](int k, const char* name) { return m->weights.Group(*layout.FindGroup("L" + std::to_string(k) + "." + name)); };
  for (size_t k = 0; k < K; ++k) {
    const std::string L = "L" + std::to_string(k);
    auto wf = NrlMatrixFile::Open((dir / (L + "_w_p.d")).string());
    if (!wf.ok()) return wf.status();
    const int d = spec.layers[k].d, z = spec.layers[k].z;
    struct Item { const char* name; int rows, cols; };
    std::vector<Item> items = {{"W_dh", d, d}, {"W_zh", d, z}, {"W_mu_p", z, d}, {"W_ls_p", z, d}, {"W_mu_q", z, d}, {"W_ls_q", z, d}};
    if (k > 0) items.push_back({"W_below", d, spec.layers[k - 1].d});
    if (k + 1 < K) items.push_back({"W_above", d, spec.layers[k + 1].d});
    // NRL's Beta network (network=pvrnnbeta) writes no W_below: every layer above the lowest is one line short.
    if (k > 0 && wf->size() + 1 == items.size())
      return Status::DataLoss(wf->name() + ": " + std::to_string(wf->size()) + " lines, a layer above the lowest needs " +
                              std::to_string(items.size()) + " (with W_below); NRL's PV-RNN Beta network " +
                              "(network=pvrnnbeta) writes no W_below: a Beta model cannot be imported, only network=pvrnn");
    for (const auto& it : items) {
      if (Status s = wf->Next(it.rows, it.cols, it.name, &buf); !s.ok()) return s;
      group(static_cast<int>(k), it.name) = buf;
    }
    auto bf = NrlMatrixFile::Open((dir / (L + "_b_p.d")).string());
    if (!bf.ok()) return bf.status();
    for (const auto& it : std::vector<Item>{{"b_h", d, 1}, {"b_mu_p", z, 1}, {"b_ls_p", z, 1}, {"b_mu_q", z, 1}, {"b_ls_q", z, 1}}) {
      if (Status s = bf->Next(it.rows, it.cols, it.name, &buf); !s.ok()) return s;
      group(static_cast<int>(k), it.name) = buf;
    }
    for (auto [suffix, view] : {std::pair{"_au_p.d", m->adaptive.mu()}, std::pair{"_al_p.d", m->adaptive.log_sigma()}}) {
      auto af = NrlMatrixFile::Open((dir / (L + suffix)).string());
      if (!af.ok()) return af.status();
      for (int p = 0; p < prims; ++p)
        for (int t = 0; t < steps; ++t) {
          if (Status s = af->Next(z, 1, "A of primitive " + std::to_string(p) + " step " + std::to_string(t), &buf); !s.ok()) return s;
          view.col(m->adaptive.Column(t, p)).segment(layout.z_offset(static_cast<int>(k)), z) = buf.col(0);
        }
    }
  }
  for (int o = 0; o < spec.num_dofs(); ++o) {
    const std::string O = "o" + std::to_string(o);
    auto wf = NrlMatrixFile::Open((dir / (O + "_w_p.d")).string());
    if (!wf.ok()) return wf.status();
    const int n = layout.output_units(o);
    if (Status s = wf->Next(n, spec.layers[0].d, "W_x", &buf); !s.ok()) return s;
    m->weights.Group(*layout.FindGroup("out.W_x" + std::to_string(o))) = buf;
    auto bf = NrlMatrixFile::Open((dir / (O + "_b_p.d")).string());
    if (!bf.ok()) return bf.status();
    if (Status s = bf->Next(n, 1, "b_x", &buf); !s.ok()) return s;
    m->weights.Group(*layout.FindGroup("out.b_x" + std::to_string(o))) = buf;
  }
  return Status::OK();
}

}  // namespace

StatusOr<std::vector<std::pair<std::string, std::string>>> ReadKeyValueFile(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return Status::InvalidArgument(path + ": is a folder, not a file");
  std::ifstream in(path);
  if (!in) return Status::NotFound(path + ": cannot open");
  std::vector<std::pair<std::string, std::string>> out;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    const std::string_view t = Trim(std::string_view(line).substr(0, line.find('#')));
    if (t.empty()) continue;
    const size_t eq = t.find('=');
    if (eq == std::string_view::npos) return Status::DataLoss(path + ":" + std::to_string(n) + ": expected key=value");
    out.emplace_back(Trim(t.substr(0, eq)), Trim(t.substr(eq + 1)));
  }
  return out;
}

StatusOr<Model> ImportNrlModel(const NrlImportOptions& options) {
  const std::string& pf = options.properties_file;
  auto properties = ReadProperties(pf);
  if (!properties.ok()) return properties.status();
  const ModelSpec& spec = properties->spec;

  auto data = LoadNrlDataset(options.dataset_dir);
  if (!data.ok()) return data.status();
  if (data->dofs() != spec.num_dofs())
    return Status::InvalidArgument(options.dataset_dir + ": " + std::to_string(data->dofs()) + " DOFs, properties activate " +
                                   std::to_string(spec.num_dofs()));
  const int prims = data->primitives(), steps = data->steps();  // NRL: one A per primitive, whatever its samples

  NetworkLayout layout(spec);
  Model m;
  m.spec = spec;
  m.weights = Weights<double>(layout);
  m.adaptive = AdaptiveVariables<double>(layout.total_z(), steps, prims);
  const fs::path dir(options.model_dir);
  if (Status st = ReadWeights(dir, layout, &m); !st.ok()) return st;
  m.provenance.source = "import-nrl " + options.model_dir;
  m.provenance.dataset = options.dataset_dir;
  m.provenance.scalar = "float";
  m.provenance.epochs = properties->epochs;
  // epoch.d: "<last saved epoch>,<loss>" (NRL saves greedily: the best loss seen).
  if (std::ifstream ef(dir / "epoch.d"); ef) {
    std::string line;
    std::getline(ef, line);
    auto v = Numbers("epoch.d", "epoch", line);
    if (v.ok() && v->size() >= 2) {
      m.provenance.epochs = static_cast<int64_t>(v.value()[0]);
      m.provenance.final_loss = v.value()[1];
    }
  }
  return m;
}

}  // namespace dyad::pvrnn
