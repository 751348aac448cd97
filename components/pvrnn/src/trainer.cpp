#include "dyad/pvrnn/trainer.hpp"

#include <numeric>
#include <sstream>

#include "dyad/pvrnn/prior_generator.hpp"
#include "dyad/pvrnn/softmax_encoding.hpp"

namespace dyad::pvrnn {

template <typename Scalar>
StatusOr<std::unique_ptr<Trainer<Scalar>>> Trainer<Scalar>::Create(const Model& model,
                                                                   const Dataset& data,
                                                                   const TrainerOptions& options) {
  if (Status s = model.spec.Validate(); !s.ok()) return s;
  if (Status s = options.adam.Validate(); !s.ok()) return s;
  if (data.size() == 0) return Status::InvalidArgument("dataset " + data.name + ": no sequences");
  if (data.dofs() != model.spec.num_dofs())
    return Status::InvalidArgument("dataset " + data.name + ": " + std::to_string(data.dofs()) + " DOFs, the model has " +
                                   std::to_string(model.spec.num_dofs()));
  if (data.size() != model.sequences() || data.steps() != model.steps())
    return Status::InvalidArgument("dataset " + data.name + ": " + std::to_string(data.size()) + " sequences x " +
                                   std::to_string(data.steps()) + " steps, the model's A has " +
                                   std::to_string(model.sequences()) + " x " + std::to_string(model.steps()));
  for (const auto& s : data.sequences)
    if (s.cols() != data.steps()) return Status::InvalidArgument("dataset " + data.name + ": sequences differ in length");
  // Far outside its DOF's range a position's softmax code underflows to 0 and the loss to NaN.
  // NRL's data sets overshoot a little (Macaw: up to 51.4 on -50..50): allow half the range.
  for (int p = 0; p < data.size(); ++p)
    for (int t = 0; t < data.steps(); ++t)
      for (int i = 0; i < data.dofs(); ++i) {
        const DofRange& r = model.spec.output.dofs[i];
        const double v = data.sequences[p](i, t), margin = 0.5 * (r.max - r.min);
        if (!(v >= r.min - margin && v <= r.max + margin)) {
          std::ostringstream m;
          m << "dataset " << data.name << ": primitive " << p << ", step " << t << " (row " << t + 1 << "), DOF " << i
            << " = " << v << ": outside the encoding range [" << r.min << ", " << r.max
            << "] by more than half its width";
          return Status::InvalidArgument(m.str());
        }
      }
  return std::unique_ptr<Trainer>(new Trainer(model, data, options));
}

template <typename Scalar>
Trainer<Scalar>::Trainer(const Model& model, const Dataset& data, const TrainerOptions& options)
    : base_(model),
      options_(options),
      layout_(model.spec),
      w_(model.weights.Cast<Scalar>()),
      grad_w_(layout_),
      a_(model.adaptive.Cast<Scalar>()),
      grad_a_(layout_.total_z(), model.steps(), model.sequences()),
      adam_w_(layout_.num_weights(), options.adam),
      adam_a_(static_cast<int>(a_.flat().size()), options.adam),
      pass_(layout_, model.steps(), model.sequences()),
      rng_(options.seed) {
  w_.ApplyMask();
  const int S = data.size(), T = data.steps();
  Eigen::MatrixXd positions(data.dofs(), T * S);
  for (int t = 0; t < T; ++t)
    for (int s = 0; s < S; ++s) positions.col(t * S + s) = data.sequences[s].col(t);
  targets_ = EncodePositions(model.spec.output, positions).cast<Scalar>();
  eps_ = MatrixT<Scalar>::Zero(layout_.total_z(), T * S);
  start_ = NetworkState<Scalar>::Zero(layout_.total_d(), S);
  for (const auto& l : model.spec.layers) meta_prior_.push_back(l.w);
  if (model.training) {
    const auto& st = *model.training;
    adam_w_.set_step(st.adam_step);
    adam_a_.set_step(st.adam_step);
    adam_w_.m() = st.weights_m.cast<Scalar>();
    adam_w_.v() = st.weights_v.cast<Scalar>();
    adam_a_.m() = st.adaptive_m.cast<Scalar>();
    adam_a_.v() = st.adaptive_v.cast<Scalar>();
    std::istringstream in(st.rng_state);
    in >> rng_ >> normal_;  // the distribution caches a value: restore it too
  }
  base_.training.reset();
}

template <typename Scalar>
const LossTerms& Trainer<Scalar>::Epoch() {
  if (options_.sample_noise) {
    Scalar* e = eps_.data();
    for (int i = 0; i < eps_.size(); ++i) e[i] = static_cast<Scalar>(normal_(rng_));
  }
  const LossTerms& terms = pass_.Forward(w_, a_, eps_, targets_, start_, meta_prior_);
  pass_.Backward(&grad_w_, &grad_a_);
  adam_w_.Step(w_.flat(), grad_w_.flat());
  adam_a_.Step(a_.flat(), grad_a_.flat());
  return terms;
}

template <typename Scalar>
double Trainer<Scalar>::PriorReconstruction(bool noise, uint64_t seed, int a_steps) const {
  std::vector<int> all(a_.sequences());
  std::iota(all.begin(), all.end(), 0);
  const MatrixT<Scalar> x = GenerateCodes(w_, a_, all, a_.steps(), GenerateOptions{a_steps, noise, seed});
  const auto y = targets_.array();
  return static_cast<double>((y * (y.log() - x.array().log())).sum());
}

template <typename Scalar>
Model Trainer<Scalar>::Snapshot(bool with_training_state) const {
  Model m = base_;
  m.weights = w_.template Cast<double>();
  m.adaptive = a_.template Cast<double>();
  if (with_training_state) {
    TrainingState st;
    st.adam_step = adam_w_.step();
    st.weights_m = adam_w_.m().template cast<double>();
    st.weights_v = adam_w_.v().template cast<double>();
    st.adaptive_m = adam_a_.m().template cast<double>();
    st.adaptive_v = adam_a_.v().template cast<double>();
    std::ostringstream out;
    out << rng_ << ' ' << normal_;
    st.rng_state = out.str();
    m.training = std::move(st);
  }
  return m;
}

template class Trainer<float>;
template class Trainer<double>;

}  // namespace dyad::pvrnn
