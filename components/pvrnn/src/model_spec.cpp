#include "dyad/pvrnn/model_spec.hpp"

#include <cmath>
#include <sstream>

namespace dyad::pvrnn {

int OutputEncoding::UnitsFor(int dof) const {
  const DofRange& r = dofs[dof];
  const int n = static_cast<int>(std::ceil((r.max - r.min) / dsoft - 1e-9));
  return n < 2 ? 2 : n;
}

int OutputEncoding::TotalUnits() const {
  int n = 0;
  for (int i = 0; i < static_cast<int>(dofs.size()); ++i) n += UnitsFor(i);
  return n;
}

int ModelSpec::total_d() const {
  int n = 0;
  for (const auto& l : layers) n += l.d;
  return n;
}

int ModelSpec::total_z() const {
  int n = 0;
  for (const auto& l : layers) n += l.z;
  return n;
}

Status ModelSpec::Validate() const {
  auto bad = [](const std::string& field, double value, const char* rule) {
    std::ostringstream s;
    s << field << " = " << value << ": " << rule;
    return Status::InvalidArgument(s.str());
  };
  if (layers.empty()) return Status::InvalidArgument("layers: must list at least one layer");
  for (size_t k = 0; k < layers.size(); ++k) {
    const std::string p = "layers[" + std::to_string(k) + "].";
    if (layers[k].d <= 0 || layers[k].d > 100000) return bad(p + "d", layers[k].d, "must be in 1..100000");
    if (layers[k].z <= 0 || layers[k].z > 100000) return bad(p + "z", layers[k].z, "must be in 1..100000");
    if (!(layers[k].tau >= 1.0)) return bad(p + "tau", layers[k].tau, "must be >= 1");
    if (!(layers[k].w >= 0.0)) return bad(p + "w", layers[k].w, "must be >= 0");
  }
  if (output.dofs.empty()) return Status::InvalidArgument("output.dofs: must list at least one DOF");
  for (size_t i = 0; i < output.dofs.size(); ++i) {
    if (!(output.dofs[i].max > output.dofs[i].min) || !std::isfinite(output.dofs[i].max - output.dofs[i].min))
      return bad("output.dofs[" + std::to_string(i) + "].max", output.dofs[i].max, "must be finite and > min");
  }
  if (!(output.dsoft > 0)) return bad("output.dsoft", output.dsoft, "must be > 0");
  if (!(output.sigma > 0)) return bad("output.sigma", output.sigma, "must be > 0");
  for (size_t i = 0; i < output.dofs.size(); ++i) {
    if ((output.dofs[i].max - output.dofs[i].min) / output.dsoft > 10000)
      return bad("output.dsoft", output.dsoft, "gives more than 10000 softmax units per DOF");
  }
  return Status::OK();
}

ModelSpec ModelSpec::MacawBot() {
  ModelSpec s;
  s.layers = {LayerSpec{40, 4, 2.0, 0.01}, LayerSpec{10, 1, 10.0, 0.01}};
  s.output.dofs = {DofRange{-50, 50}, DofRange{-50, 50}};
  s.output.dsoft = 10;
  s.output.sigma = 0.2;
  return s;
}

bool ModelSpec::operator==(const ModelSpec& o) const {
  if (layers.size() != o.layers.size() || output.dofs.size() != o.output.dofs.size()) return false;
  for (size_t k = 0; k < layers.size(); ++k) {
    const auto &a = layers[k], &b = o.layers[k];
    if (a.d != b.d || a.z != b.z || a.tau != b.tau || a.w != b.w) return false;
  }
  for (size_t i = 0; i < output.dofs.size(); ++i)
    if (output.dofs[i].min != o.output.dofs[i].min || output.dofs[i].max != o.output.dofs[i].max) return false;
  return output.dsoft == o.output.dsoft && output.sigma == o.output.sigma;
}

}  // namespace dyad::pvrnn
