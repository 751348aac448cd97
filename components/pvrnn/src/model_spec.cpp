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

namespace {

std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

std::vector<FieldProblem> ModelSpec::Problems() const {
  std::vector<FieldProblem> out;
  auto bad = [&out](std::string field, const std::string& rule, double value) {
    out.push_back({std::move(field), rule + ", got " + Num(value)});
  };
  if (layers.empty()) out.push_back({"layers", "must list at least one layer"});
  for (size_t k = 0; k < layers.size(); ++k) {
    const std::string p = "layers[" + std::to_string(k) + "].";
    const LayerSpec& l = layers[k];
    if (l.d < 1 || l.d > 100000) bad(p + "d", "must be in 1..100000", l.d);
    if (l.z < 1 || l.z > 100000) bad(p + "z", "must be in 1..100000", l.z);
    if (!(std::isfinite(l.tau) && l.tau >= 1.0)) bad(p + "tau", "must be finite and >= 1", l.tau);
    if (!(std::isfinite(l.w) && l.w >= 0.0)) bad(p + "w", "must be finite and >= 0", l.w);
  }
  if (output.dofs.empty()) out.push_back({"output.dofs", "must list at least one DOF"});
  bool ranges_ok = true;
  for (size_t i = 0; i < output.dofs.size(); ++i) {
    const DofRange& r = output.dofs[i];
    if (!(std::isfinite(r.min) && std::isfinite(r.max) && r.max > r.min)) {
      ranges_ok = false;
      out.push_back({"output.dofs[" + std::to_string(i) + "]",
                     "must be [min, max] with finite min < max, got [" + Num(r.min) + ", " + Num(r.max) + "]"});
    }
  }
  if (!(std::isfinite(output.dsoft) && output.dsoft > 0)) {
    bad("output.dsoft", "must be finite and > 0", output.dsoft);
  } else if (ranges_ok) {
    for (const DofRange& r : output.dofs)
      if ((r.max - r.min) / output.dsoft > 10000) {
        bad("output.dsoft", "gives more than 10000 softmax units per DOF", output.dsoft);
        break;
      }
  }
  if (!(std::isfinite(output.sigma) && output.sigma > 0)) bad("output.sigma", "must be finite and > 0", output.sigma);
  if (out.empty()) {  // sizes are ints throughout the engine: bound the whole model
    int64_t td = 0, tz = 0, units = 0;
    for (const LayerSpec& l : layers) td += l.d, tz += l.z;
    for (int i = 0; i < num_dofs(); ++i) units += output.UnitsFor(i);
    const int64_t rr = td + 4 * tz;
    const int64_t weights = rr * td + rr + td * tz + units * layers[0].d + units;
    if (weights > kMaxWeights)
      out.push_back({"layers", "the model would have " + std::to_string(weights) + " weights, more than " +
                                   std::to_string(kMaxWeights)});
  }
  return out;
}

Status ModelSpec::Validate() const {
  const std::vector<FieldProblem> p = Problems();
  return p.empty() ? Status::OK() : Status::InvalidArgument(p.front().ToString());
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
