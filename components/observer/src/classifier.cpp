#include "dyad/observer/classifier.hpp"

#include <cmath>
#include <random>

namespace dyad::observer {

const char* ToString(InputRepresentation r) {
  return r == InputRepresentation::kDisplacements ? "displacements" : "positions";
}

bool ParseInputRepresentation(const std::string& text, InputRepresentation* out) {
  if (text == "positions") *out = InputRepresentation::kPositions;
  else if (text == "displacements") *out = InputRepresentation::kDisplacements;
  else return false;
  return true;
}

int64_t ClassifierSpec::num_parameters() const {
  int64_t n = 0;
  int in = inputs();
  for (int h : hidden) {
    n += int64_t{h} * in + h;
    in = h;
  }
  return n + int64_t{classes} * in + classes;
}

std::vector<FieldProblem> ClassifierSpec::Problems() const {
  std::vector<FieldProblem> p;
  auto range = [&](const std::string& field, int v, int lo, int hi) {
    if (v < lo || v > hi)
      p.push_back({field, "must be in " + std::to_string(lo) + ".." + std::to_string(hi) + ", got " + std::to_string(v)});
  };
  range("window", window, 1, 1000);
  range("classes", classes, 1, 1000);
  if (hidden.empty()) p.push_back({"hidden", "must list at least one layer"});
  for (size_t i = 0; i < hidden.size(); ++i) range("hidden[" + std::to_string(i) + "]", hidden[i], 1, 100000);
  if (workspace.empty()) p.push_back({"workspace", "must list at least one DOF"});
  for (size_t i = 0; i < workspace.size(); ++i) {
    const auto& r = workspace[i];
    if (!std::isfinite(r.min) || !std::isfinite(r.max) || !(r.min < r.max))
      p.push_back({"workspace[" + std::to_string(i) + "]",
                   "must be finite with min < max, got [" + std::to_string(r.min) + ", " + std::to_string(r.max) + "]"});
  }
  return p;
}

Status ClassifierSpec::Validate() const {
  const auto p = Problems();
  return p.empty() ? Status::OK() : Status::InvalidArgument(p.front().ToString());
}

bool ClassifierSpec::operator==(const ClassifierSpec& o) const {
  if (window != o.window || hidden != o.hidden || classes != o.classes || input != o.input ||
      workspace.size() != o.workspace.size())
    return false;
  for (size_t i = 0; i < workspace.size(); ++i)
    if (workspace[i].min != o.workspace[i].min || workspace[i].max != o.workspace[i].max) return false;
  return true;
}

void ComputeFeatures(const ClassifierSpec& spec, const Eigen::Ref<const Eigen::MatrixXd>& positions,
                     Eigen::Ref<Eigen::VectorXd> out) {
  const int dofs = spec.dofs();
  for (int t = 0; t < spec.window; ++t) {
    for (int i = 0; i < dofs; ++i) {
      const DofRange& r = spec.workspace[static_cast<size_t>(i)];
      const double width = r.max - r.min;
      double v;
      if (spec.input == InputRepresentation::kPositions) {
        v = 2.0 * (positions(i, t) - r.min) / width - 1.0;
      } else {
        v = (positions(i, t + 1) - positions(i, t)) / (0.05 * width);
      }
      out(t * dofs + i) = v;
    }
  }
}

Classifier::Classifier(const ClassifierSpec& spec) : spec_(spec) {
  int in = spec.inputs();
  int64_t at = 0;
  std::vector<int> outs = spec.hidden;
  outs.push_back(spec.classes);
  for (int out : outs) {
    LayerView v;
    v.w = at;
    v.b = at + int64_t{out} * in;
    v.in = in;
    v.out = out;
    at = v.b + out;
    layers_.push_back(v);
    in = out;
  }
}

StatusOr<Classifier> Classifier::Create(const ClassifierSpec& spec, uint64_t seed) {
  if (Status s = spec.Validate(); !s.ok()) return s;
  Classifier c(spec);
  c.params_ = Eigen::VectorXd::Zero(spec.num_parameters());
  std::mt19937_64 rng(seed);
  for (const LayerView& l : c.layers_) {
    const double a = std::sqrt(6.0 / (l.in + l.out));
    std::uniform_real_distribution<double> u(-a, a);
    for (int64_t k = 0; k < int64_t{l.in} * l.out; ++k) c.params_(l.w + k) = u(rng);
  }
  return c;
}

StatusOr<Classifier> Classifier::FromParameters(const ClassifierSpec& spec, Eigen::VectorXd parameters) {
  if (Status s = spec.Validate(); !s.ok()) return s;
  if (parameters.size() != spec.num_parameters())
    return Status::InvalidArgument("classifier: " + std::to_string(parameters.size()) + " parameters given, the shape needs " +
                                   std::to_string(spec.num_parameters()));
  Classifier c(spec);
  c.params_ = std::move(parameters);
  return c;
}

Eigen::Map<const Eigen::MatrixXd> Classifier::W(int l) const {
  const LayerView& v = layers_[static_cast<size_t>(l)];
  return {params_.data() + v.w, v.out, v.in};
}

Eigen::Map<const Eigen::VectorXd> Classifier::B(int l) const {
  const LayerView& v = layers_[static_cast<size_t>(l)];
  return {params_.data() + v.b, v.out};
}

namespace {
double Sigmoid(double z) { return z >= 0 ? 1.0 / (1.0 + std::exp(-z)) : std::exp(z) / (1.0 + std::exp(z)); }
double Softplus(double z) { return std::max(z, 0.0) + std::log1p(std::exp(-std::abs(z))); }
}  // namespace

Eigen::MatrixXd Classifier::Probabilities(const Eigen::MatrixXd& features) const {
  Eigen::MatrixXd a = features;
  const int last = static_cast<int>(layers_.size()) - 1;
  for (int l = 0; l < last; ++l) a = ((W(l) * a).colwise() + B(l)).array().tanh().matrix();
  Eigen::MatrixXd z = (W(last) * a).colwise() + B(last);
  return z.unaryExpr([](double v) { return Sigmoid(v); });
}

double Classifier::Loss(const Eigen::MatrixXd& features, const Eigen::MatrixXd& targets, Eigen::VectorXd* gradient) const {
  const int n_layers = static_cast<int>(layers_.size());
  const int last = n_layers - 1;
  const double n = static_cast<double>(features.cols());
  std::vector<Eigen::MatrixXd> acts(static_cast<size_t>(n_layers));  // acts[l] = input of layer l
  acts[0] = features;
  for (int l = 0; l < last; ++l)
    acts[static_cast<size_t>(l + 1)] = ((W(l) * acts[static_cast<size_t>(l)]).colwise() + B(l)).array().tanh().matrix();
  const Eigen::MatrixXd z = (W(last) * acts[static_cast<size_t>(last)]).colwise() + B(last);
  double loss = 0;
  for (Eigen::Index j = 0; j < z.cols(); ++j)
    for (Eigen::Index k = 0; k < z.rows(); ++k) loss += Softplus(z(k, j)) - targets(k, j) * z(k, j);
  loss /= n;
  if (gradient == nullptr) return loss;

  gradient->setZero(params_.size());
  // dL/dz of the output layer: (sigmoid(z) - y) / N.
  Eigen::MatrixXd delta = (z.unaryExpr([](double v) { return Sigmoid(v); }) - targets) / n;
  for (int l = last; l >= 0; --l) {
    const LayerView& v = layers_[static_cast<size_t>(l)];
    const Eigen::MatrixXd& in = acts[static_cast<size_t>(l)];
    Eigen::Map<Eigen::MatrixXd>(gradient->data() + v.w, v.out, v.in).noalias() = delta * in.transpose();
    Eigen::Map<Eigen::VectorXd>(gradient->data() + v.b, v.out) = delta.rowwise().sum();
    if (l > 0) {
      Eigen::MatrixXd back = W(l).transpose() * delta;
      delta = back.array() * (1.0 - in.array().square());  // in = tanh(...) of layer l-1
    }
  }
  return loss;
}

void Classifier::Classify(const Eigen::Ref<const Eigen::MatrixXd>& positions, Workspace* ws,
                          Eigen::VectorXd* probabilities) const {
  const int n_layers = static_cast<int>(layers_.size());
  ws->features.resize(spec_.inputs());
  ComputeFeatures(spec_, positions, ws->features);
  ws->activations.resize(static_cast<size_t>(n_layers));
  const Eigen::VectorXd* in = &ws->features;
  for (int l = 0; l < n_layers; ++l) {
    Eigen::VectorXd& a = ws->activations[static_cast<size_t>(l)];
    a.resize(layers_[static_cast<size_t>(l)].out);
    a.noalias() = W(l) * *in;
    a += B(l);
    if (l + 1 < n_layers) a = a.array().tanh();
    in = &a;
  }
  probabilities->resize(spec_.classes);
  for (int k = 0; k < spec_.classes; ++k) (*probabilities)(k) = Sigmoid((*in)(k));
}

}  // namespace dyad::observer
