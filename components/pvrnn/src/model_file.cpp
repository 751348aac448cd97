#include "dyad/pvrnn/model_file.hpp"

#include <nlohmann/json.hpp>

#include <sstream>

#include "dyad/pvrnn/checked_file.hpp"
#include "dyad/pvrnn/json_fields.hpp"

namespace dyad::pvrnn {
namespace {

using nlohmann::json;
constexpr char kMagic[8] = {'D', 'Y', 'A', 'D', 'P', 'V', 'R', 'N'};

json SpecToJson(const ModelSpec& s) {
  json layers = json::array();
  for (const auto& l : s.layers) layers.push_back({{"d", l.d}, {"z", l.z}, {"tau", l.tau}, {"w", l.w}});
  json dofs = json::array();
  for (const auto& r : s.output.dofs) dofs.push_back({r.min, r.max});
  return {{"layers", layers}, {"output", {{"dofs", dofs}, {"dsoft", s.output.dsoft}, {"sigma", s.output.sigma}}}};
}

ModelSpec SpecFromJson(const json& j) {
  ModelSpec s;
  for (const auto& l : j.at("layers"))
    s.layers.push_back({JsonInt<int>(l, "d"), JsonInt<int>(l, "z"), l.at("tau").get<double>(), l.at("w").get<double>()});
  for (const auto& r : j.at("output").at("dofs")) s.output.dofs.push_back({r.at(0).get<double>(), r.at(1).get<double>()});
  s.output.dsoft = j.at("output").at("dsoft").get<double>();
  s.output.sigma = j.at("output").at("sigma").get<double>();
  return s;
}

// NaN is not JSON: store it as null.
json Num(double v) { return std::isnan(v) ? json(nullptr) : json(v); }
double NumFrom(const json& j) { return j.is_null() ? std::numeric_limits<double>::quiet_NaN() : j.get<double>(); }

struct Tensor {
  std::string name;
  int rows, cols;
  const double* data;
};

// The number of values the header's tensors span, each tensor's extent checked against the
// payload (and the checksum, once the extents fit); DataLoss naming the path otherwise. Throws
// on a malformed header (the caller catches).
StatusOr<uint64_t> TensorExtent(const json& header, const std::string& path, const CheckedFileView& view) {
  // Each tensor's extent is checked against the payload before anything is summed or
  // multiplied: huge offsets or shapes must not wrap around into something that fits.
  const size_t payload_bytes = view.payload_bytes;
  const uint64_t payload_values = payload_bytes / 8;
  uint64_t needed = 0;
  for (const auto& t : header.at("tensors")) {
    const uint64_t offset = JsonInt<uint64_t>(t, "offset"), rows = JsonInt<uint64_t>(t, "rows"),
                   cols = JsonInt<uint64_t>(t, "cols");
    if ((cols != 0 && rows > payload_values / cols) || offset > payload_values - rows * cols)
      return Status::DataLoss(path + ": truncated: tensor " + t.at("name").get<std::string>() + " (offset " +
                              std::to_string(offset) + ", " + std::to_string(rows) + " x " + std::to_string(cols) +
                              ") does not fit in the payload of " + std::to_string(payload_bytes) + " bytes");
    needed = std::max<uint64_t>(needed, offset + rows * cols);
  }
  if (needed * 8 > payload_bytes)
    return Status::DataLoss(path + ": truncated: tensors need " + std::to_string(needed * 8) + " bytes, file has " +
                             std::to_string(payload_bytes));
  if (!view.crc_ok) return Status::DataLoss(path + ": corrupted (checksum mismatch)");
  if (needed * 8 != payload_bytes)
    return Status::DataLoss(path + ": " + std::to_string(payload_bytes - needed * 8) + " unexpected bytes after the tensors");
  return needed;
}

// The model's provenance from the header's "provenance" object. Throws on a malformed one.
void ReadProvenance(const json& p, Model* m) {
  m->provenance.source = p.at("source").get<std::string>();
  m->provenance.dataset = p.at("dataset").get<std::string>();
  m->provenance.epochs = JsonInt<int64_t>(p, "epochs");
  m->provenance.seed = JsonInt<uint64_t>(p, "seed");
  m->provenance.scalar = p.at("scalar").get<std::string>();
  m->provenance.final_loss = NumFrom(p.at("final_loss"));
  m->provenance.final_reconstruction = NumFrom(p.at("final_reconstruction"));
  m->provenance.final_regulation = NumFrom(p.at("final_regulation"));
}

}  // namespace

Status SaveModel(const Model& model, const std::string& path) {
  NetworkLayout layout(model.spec);
  std::vector<Tensor> tensors;
  std::vector<Eigen::MatrixXd> keep;  // contiguous copies of strided groups
  keep.reserve(layout.groups().size());
  for (const auto& g : layout.groups()) {
    keep.emplace_back(model.weights.Group(g));
    tensors.push_back({g.name, g.rows, g.cols, keep.back().data()});
  }
  const auto& a = model.adaptive;
  tensors.push_back({"A.mu", a.total_z(), a.cols(), a.mu().data()});
  tensors.push_back({"A.log_sigma", a.total_z(), a.cols(), a.log_sigma().data()});
  json training = nullptr;
  if (model.training) {
    const auto& t = *model.training;
    tensors.push_back({"adam.weights.m", static_cast<int>(t.weights_m.size()), 1, t.weights_m.data()});
    tensors.push_back({"adam.weights.v", static_cast<int>(t.weights_v.size()), 1, t.weights_v.data()});
    tensors.push_back({"adam.adaptive.m", static_cast<int>(t.adaptive_m.size()), 1, t.adaptive_m.data()});
    tensors.push_back({"adam.adaptive.v", static_cast<int>(t.adaptive_v.size()), 1, t.adaptive_v.data()});
    training = {{"adam_step", t.adam_step}, {"rng_state", t.rng_state}};
  }
  json table = json::array();
  uint64_t offset = 0;
  for (const auto& t : tensors) {
    table.push_back({{"name", t.name}, {"rows", t.rows}, {"cols", t.cols}, {"offset", offset}});
    offset += static_cast<uint64_t>(t.rows) * t.cols;
  }
  const auto& p = model.provenance;
  json header = {
      {"format", "dyad PV-RNN model"},
      {"spec", SpecToJson(model.spec)},
      {"steps", a.steps()},
      {"sequences", a.sequences()},
      {"provenance",
       {{"source", p.source}, {"dataset", p.dataset}, {"epochs", p.epochs}, {"seed", p.seed},
        {"scalar", p.scalar}, {"final_loss", Num(p.final_loss)},
        {"final_reconstruction", Num(p.final_reconstruction)}, {"final_regulation", Num(p.final_regulation)}}},
      {"tensors", table},
      {"training", training},
  };
  std::string out = BeginCheckedFile(kMagic, kModelFileVersion, header.dump(1));
  out.reserve(out.size() + offset * 8 + 4);
  for (const auto& t : tensors)
    for (int64_t i = 0; i < static_cast<int64_t>(t.rows) * t.cols; ++i) AppendDouble(out, t.data[i]);
  return FinishCheckedFile(out, path);
}

StatusOr<Model> LoadModel(const std::string& path) {
  auto bytes = ReadWholeFile(path, "model file");
  if (!bytes.ok()) return bytes.status();
  const std::string& in = *bytes;
  auto view = OpenCheckedFile(in, path, kMagic, kModelFileVersion, "dyad PV-RNN model file");
  if (!view.ok()) return view.status();
  json header;
  try {
    header = json::parse(view->json);
  } catch (const std::exception& e) {
    if (!view->crc_ok) return Status::DataLoss(path + ": corrupted or truncated (checksum mismatch)");
    return Status::DataLoss(path + ": unreadable header: " + e.what());
  }
  const size_t payload_at = view->payload_at;
  Model m;
  try {
    auto extent = TensorExtent(header, path, *view);
    if (!extent.ok()) return extent.status();
    const uint64_t needed = *extent;
    m.spec = SpecFromJson(header.at("spec"));
    if (Status s = m.spec.Validate(); !s.ok()) return Status::DataLoss(path + ": spec: " + s.message());
    const int steps = JsonInt<int>(header, "steps"), sequences = JsonInt<int>(header, "sequences");
    if (steps < 0 || sequences < 0) return Status::DataLoss(path + ": negative steps or sequences");
    NetworkLayout layout(m.spec);
    // Every tensor was checked against the payload above; check the shapes it claims before
    // allocating them (a consistent, checksummed header could still claim too much).
    uint64_t stored = 0;  // the file holds the named groups, not R's structural zeros
    for (const auto& g : layout.groups()) stored += static_cast<uint64_t>(g.rows) * static_cast<uint64_t>(g.cols);
    const uint64_t a_cols = static_cast<uint64_t>(steps) * static_cast<uint64_t>(sequences);
    if (a_cols > needed || stored + 2 * a_cols * static_cast<uint64_t>(layout.total_z()) > needed)
      return Status::DataLoss(path + ": the spec, steps and sequences need more values than the tensors hold");
    m.weights = Weights<double>(layout);
    m.adaptive = AdaptiveVariables<double>(layout.total_z(), steps, sequences);
    auto read = [&](const std::string& name, int rows, int cols, auto&& sink) -> Status {
      for (const auto& t : header.at("tensors")) {
        if (t.at("name").get<std::string>() != name) continue;
        if (JsonInt<uint64_t>(t, "rows") != static_cast<uint64_t>(rows) || JsonInt<uint64_t>(t, "cols") != static_cast<uint64_t>(cols))
          return Status::DataLoss(path + ": tensor " + name + " is " + std::to_string(JsonInt<uint64_t>(t, "rows")) + " x " +
                                   std::to_string(JsonInt<uint64_t>(t, "cols")) + ", the spec needs " + std::to_string(rows) +
                                   " x " + std::to_string(cols));
        const size_t at = payload_at + JsonInt<size_t>(t, "offset") * 8;  // checked to fit above
        for (int c = 0; c < cols; ++c)
          for (int r = 0; r < rows; ++r) sink(r, c, ReadDouble(in, at + (static_cast<size_t>(c) * rows + r) * 8));
        return Status::OK();
      }
      return Status::DataLoss(path + ": tensor " + name + " missing");
    };
    for (const auto& g : layout.groups()) {
      auto view = m.weights.Group(g);
      if (Status s = read(g.name, g.rows, g.cols, [&](int r, int c, double v) { view(r, c) = v; }); !s.ok()) return s;
    }
    auto mu = m.adaptive.mu();
    auto ls = m.adaptive.log_sigma();
    if (Status s = read("A.mu", layout.total_z(), m.adaptive.cols(), [&](int r, int c, double v) { mu(r, c) = v; }); !s.ok()) return s;
    if (Status s = read("A.log_sigma", layout.total_z(), m.adaptive.cols(), [&](int r, int c, double v) { ls(r, c) = v; }); !s.ok()) return s;
    ReadProvenance(header.at("provenance"), &m);
    if (!header.at("training").is_null()) {
      TrainingState t;
      t.adam_step = JsonInt<int64_t>(header.at("training"), "adam_step");
      t.rng_state = header.at("training").at("rng_state").get<std::string>();
      const int nw = layout.num_weights(), na = static_cast<int>(m.adaptive.flat().size());
      t.weights_m.resize(nw); t.weights_v.resize(nw); t.adaptive_m.resize(na); t.adaptive_v.resize(na);
      for (auto [name, vec, n] : {std::tuple{"adam.weights.m", &t.weights_m, nw}, std::tuple{"adam.weights.v", &t.weights_v, nw},
                                  std::tuple{"adam.adaptive.m", &t.adaptive_m, na}, std::tuple{"adam.adaptive.v", &t.adaptive_v, na}}) {
        auto* v = vec;
        if (Status s = read(name, n, 1, [&](int r, int, double x) { (*v)[r] = x; }); !s.ok()) return s;
      }
      m.training = std::move(t);
    }
  } catch (const std::exception& e) {
    return Status::DataLoss(path + ": malformed header: " + e.what());
  }
  return m;
}

}  // namespace dyad::pvrnn
