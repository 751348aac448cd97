#include "dyad/pvrnn/nrl_regression.hpp"

#include <cmath>
#include <cstdint>
#include <limits>

#include "dyad/pvrnn/error_regression.hpp"
#include "nrl_network.hpp"

namespace dyad::pvrnn {

namespace {
using nrl::ArrF;
using nrl::VecF;

// NRL bug: NetworkPvrnn::load reads the output weights Wdo but not their transposes
// Wdo_transpose (set from the random initial Wdo in the constructor, NetworkPvrnn.cpp:133-137, and
// refreshed only by a training step, :345), and e_backward's output gradient uses the transposes
// (:716): so a loaded model's ER gradient goes back through NRL's random initial output weights,
// replayed by nrl::NrlInitialModel.
std::vector<Eigen::MatrixXf> NrlInitialOutputTransposes(const ModelSpec& spec, int primitives, int steps) {
  const Weights<float> w = nrl::NrlInitialModel(spec, steps, primitives).weights.Cast<float>();
  std::vector<Eigen::MatrixXf> w_out, out;
  std::vector<VecF> b_out;
  nrl::OutputWeights(spec, w, &w_out, &b_out);
  for (const Eigen::MatrixXf& m : w_out) out.push_back(m.transpose());
  return out;
}
}  // namespace

// One NRL layer (nrl::Layer) with its error regression state.
struct NrlRegression::Layer : nrl::Layer {
  // Window: A, its kept copy, gradients, Adam moments (W slots each).
  std::vector<VecF> au, al, au_copy, al_copy, g_au, g_al, m_au, m_al, v_au, v_al;
  VecF hq_tzero, dq_tzero, hq_opt, dq_opt;
  VecF hp_gen, dp_gen;
  int gen_time = 0;
  nrl::Trajectory tr;  // the last forward pass (W + 1 entries)

  void ResetState(int window);
  void Generate(NrlRegression* er);
};

void NrlRegression::Layer::ResetState(int window) {
  for (auto* v : {&au, &al, &au_copy, &al_copy, &g_au, &g_al, &m_au, &m_al, &v_au, &v_al}) v->assign(window, VecF::Zero(z));
  for (auto* v : {&hq_tzero, &dq_tzero, &hq_opt, &dq_opt, &hp_gen, &dp_gen}) *v = VecF::Zero(d);
  gen_time = 0;
  tr.Reset(window, d, z);
}

NrlRegression::NrlRegression(const Model& model, const ErrorRegressionOptions& o, const std::vector<double>& meta_prior)
    : window_(o.window),
      iterations_(o.iterations),
      a_steps_(o.a_steps),
      lr_(static_cast<float>(o.adam.lr)),
      beta1_(static_cast<float>(o.adam.beta1)),
      beta2_(static_cast<float>(o.adam.beta2)),
      epsilon_(static_cast<float>(o.adam.epsilon)),
      sigma_(static_cast<float>(model.spec.output.sigma)),
      noise_on_(o.noise != NoiseMode::kOff),
      noise_(std::make_unique<nrl::Noise>()) {
  const Weights<float> w = model.weights.Cast<float>();
  const AdaptiveVariables<float> a = model.adaptive.Cast<float>();
  const NetworkLayout& l = w.layout();
  const int K = l.num_layers();
  for (nrl::Layer& y : nrl::MakeLayers(model.spec, w, std::vector<float>(K, 0.0f))) {
    layers_.emplace_back();
    static_cast<nrl::Layer&>(layers_.back()) = std::move(y);
    layers_.back().ResetState(window_);
  }
  nrl::OutputWeights(model.spec, w, &w_out_, &b_out_);
  for (int dof = 0; dof < model.spec.num_dofs(); ++dof) {
    const float lo = static_cast<float>(model.spec.output.dofs[dof].min);
    const float hi = static_cast<float>(model.spec.output.dofs[dof].max);
    jmin_.push_back(lo);
    jrange_.push_back(hi - lo);
    ref_.push_back(nrl::ReferencePoints(model.spec.output.UnitsFor(dof)));
  }
  w_out_t_ = NrlInitialOutputTransposes(model.spec, model.sequences(), model.steps());
  rec_coef_ = static_cast<float>(1.0 / static_cast<float>(model.spec.num_dofs() * 1.0));
  total_z_ = l.total_z();
  reg_coef_ = static_cast<float>(1.0 / static_cast<float>(total_z_ * 1.0));
  trained_a_ = a;
  w_.assign(K, 0.0f);
  Retune(o.iterations, meta_prior);
  intention_ = Eigen::VectorXd::Zero(model.spec.num_dofs());
  outcome_.kl_per_layer.assign(K, 0.0f);
  outcome_kl_.assign(K, 0.0f);
}

NrlRegression::~NrlRegression() = default;

void NrlRegression::Retune(int iterations, const std::vector<double>& meta_prior) {
  iterations_ = iterations;
  for (size_t k = 0; k < layers_.size(); ++k) {
    const float wk = static_cast<float>(meta_prior[k]);
    layers_[k].w_div_z = static_cast<float>(wk / (static_cast<float>(total_z_) * 1.0));
    w_[k] = wk;
  }
}

const Eigen::VectorXf& NrlRegression::kept_mu(int layer, int slot) const { return layers_[layer].au_copy[slot]; }
const Eigen::VectorXf& NrlRegression::kept_log_sigma(int layer, int slot) const { return layers_[layer].al_copy[slot]; }

float NrlRegression::Decode(const Eigen::VectorXf& x, int dof) const {
  float dec = 0;
  for (size_t r = 0; r < ref_[dof].size(); ++r) dec += ref_[dof][r] * x[static_cast<Eigen::Index>(r)];
  dec *= jrange_[dof];
  dec += jmin_[dof];
  return dec;
}

// Dataset::encodeSoftmax on the window's positions.
void NrlRegression::Encode(std::vector<std::vector<Eigen::VectorXf>>* y) const {
  y->assign(buffer_.size(), {});
  for (size_t t = 0; t < buffer_.size(); ++t)
    for (size_t j = 0; j < ref_.size(); ++j) {
      const VecF enc = nrl::EncodeValue(buffer_[t][j], jmin_[j], jrange_[j], ref_[j], sigma_, true);
      (*y)[t].push_back(enc);
    }
}

// LayerPvrnn::e_generate: one step from the generator's state (posterior weights with the start
// primitive's trained A for the first a_steps calls, then the prior).
void NrlRegression::Layer::Generate(NrlRegression* er) {
  VecF h = hp_gen;
  const VecF& d_prev = dp_gen;
  VecF u, l;
  const AdaptiveVariables<float>& ta = er->trained_a_;
  if (gen_time < er->a_steps_ && gen_time < ta.steps()) {
    const int c = ta.Column(gen_time, er->primitive_);
    u = Wduq * d_prev + Buq + ta.mu().col(c).segment(z_offset, z);
    l = Wdlq * d_prev + Blq + ta.log_sigma().col(c).segment(z_offset, z);
  } else {
    u = Wdup * d_prev + Bup;
    l = Wdlp * d_prev + Blp;
  }
  gen_time += 1;
  nrl::TanH(&u);
  const VecF s = l.array().exp();
  VecF n = VecF::Zero(z);
  er->noise_->Draw(&n);
  const VecF zz = (u.array() + s.array() * n.array()).matrix();
  h = one_sub_eps * h + eps * (Wdh * d_prev + Wzh * zz + Bh);
  if (!bottom) h += eps * (Wdh_bottom * dp_bottom_prev);
  if (!top) h += eps * (Wdh_top * dp_top_prev);
  hp_gen = h;
  dp_gen = h;
  nrl::TanH(&dp_gen);
}

// NetworkPvrnn::e_generate: all layers from the previous step's d, then the output.
void NrlRegression::Generate() {
  const int K = static_cast<int>(layers_.size());
  std::vector<VecF> d_prev;
  for (const Layer& y : layers_) d_prev.push_back(y.dp_gen);
  for (int k = 0; k < K; ++k) {
    if (k > 0) layers_[k].dp_bottom_prev = d_prev[k - 1];
    if (k + 1 < K) layers_[k].dp_top_prev = d_prev[k + 1];
    layers_[k].Generate(this);
  }
  const VecF d0 = layers_[0].dp_gen;
  for (size_t o = 0; o < w_out_.size(); ++o) {
    VecF x = w_out_[o] * d0 + b_out_[o];
    nrl::Softmax(&x);
    intention_[static_cast<Eigen::Index>(o)] = Decode(x, static_cast<int>(o));
  }
}

// NetworkPvrnn::e_forward: prior path and posterior through the window from its start state.
void NrlRegression::Forward() {
  std::vector<nrl::Trajectory*> tr;
  std::vector<nrl::Layer*> layers;
  nrl::AView au, al;
  for (Layer& y : layers_) {
    layers.push_back(&y);
    y.tr.hp[0] = y.tr.hq[0] = y.hq_tzero;
    y.tr.dp[0] = y.tr.dq[0] = y.dq_tzero;
    tr.push_back(&y.tr);
    au.push_back(&y.au);
    al.push_back(&y.al);
  }
  nrl::ForwardPass(layers, tr, window_, au, al, noise_.get(), w_out_, b_out_, &x_);
}

// NetworkPvrnn::e_backward: the loss terms (float, summed backwards in time) and NRL's gradient.
void NrlRegression::Backward(const std::vector<std::vector<Eigen::VectorXf>>& y, float* rec, float* reg) {
  std::vector<nrl::Trajectory*> tr;
  std::vector<nrl::Layer*> layers;
  nrl::BackwardSinks sinks;
  for (Layer& l : layers_) {
    layers.push_back(&l);
    tr.push_back(&l.tr);
    sinks.g_au.push_back(&l.g_au);
    sinks.g_al.push_back(&l.g_al);
  }
  std::vector<float> kld;
  nrl::BackwardPass(layers, tr, window_, x_, y, w_out_t_, rec_coef_, rec, &kld, sinks);
  for (size_t k = 0; k < layers_.size(); ++k) {
    *reg += w_[k] * kld[k];
    outcome_kl_[k] = kld[k];
  }
}

void NrlRegression::AdamStep() {
  for (Layer& l : layers_)
    for (int t = 0; t < window_; ++t) {
      nrl::AdamUpdate(&l.au[t], &l.g_au[t], &l.m_au[t], &l.v_au[t], adam_step_, lr_, beta1_, beta2_, epsilon_);
      nrl::AdamUpdate(&l.al[t], &l.g_al[t], &l.m_al[t], &l.v_al[t], adam_step_, lr_, beta1_, beta2_, epsilon_);
    }
}

// LayerPvrnn::e_copyParam: the A after this iteration's Adam step, the states before it.
void NrlRegression::CopyParam() {
  for (Layer& l : layers_) {
    l.au_copy = l.au;
    l.al_copy = l.al;
    l.dp_gen = l.tr.dq[window_];
    l.hp_gen = l.tr.hq[window_];
    l.hq_opt = l.tr.hq[1];
    l.dq_opt = l.tr.dq[1];
  }
}

// LayerPvrnn::e_overwriteParam: the slide (A of slot k+1 into k, the newest 0; start state).
void NrlRegression::OverwriteParam() {
  for (Layer& l : layers_) {
    l.dq_tzero = l.dq_opt;
    l.hq_tzero = l.hq_opt;
    for (int t = 0; t + 1 < window_; ++t) {
      l.au[t] = l.au_copy[t + 1];
      l.al[t] = l.al_copy[t + 1];
    }
    l.au[window_ - 1].setZero();
    l.al[window_ - 1].setZero();
  }
}

// LibNRL::e_postdict.
void NrlRegression::Postdict(std::chrono::steady_clock::time_point deadline) {
  std::vector<std::vector<Eigen::VectorXf>> y;
  Encode(&y);
  float max_loss = std::numeric_limits<float>::max();
  for (int e1 = 1; e1 <= iterations_; ++e1, ++adam_step_) {
    if (e1 > 1 && std::chrono::steady_clock::now() >= deadline) {
      outcome_.stopped_by_deadline = true;
      break;
    }
    float rec = 0, reg = 0;
    Forward();
    Backward(y, &rec, &reg);
    const float loss = rec_coef_ * rec + reg_coef_ * reg;
    AdamStep();
    outcome_.iterations = e1;
    if (max_loss > loss) {
      outcome_.loss = loss;
      outcome_.reconstruction = rec;
      outcome_.regulation = reg;
      outcome_.kl_per_layer = outcome_kl_;
      max_loss = loss;
      CopyParam();
    }
  }
  OverwriteParam();
}

void NrlRegression::Reset(int primitive, uint64_t seed) {
  primitive_ = primitive;
  for (Layer& l : layers_) l.ResetState(window_);
  buffer_.clear();
  adam_step_ = 1;
  noise_->Reset(noise_on_, seed);
  outcome_ = Outcome{};
  outcome_.kl_per_layer.assign(layers_.size(), 0.0f);
  Generate();
}

const NrlRegression::Outcome& NrlRegression::Step(const double* executed, std::chrono::steady_clock::time_point deadline) {
  std::vector<float> xy;
  for (Eigen::Index j = 0; j < intention_.size(); ++j)
    xy.push_back(static_cast<float>(std::isfinite(executed[j]) ? executed[j] : intention_[j]));
  buffer_.push_back(xy);
  if (static_cast<int>(buffer_.size()) > window_) buffer_.erase(buffer_.begin());
  outcome_.regressed = static_cast<int>(buffer_.size()) == window_;
  outcome_.iterations = 0;
  outcome_.stopped_by_deadline = false;
  if (outcome_.regressed) Postdict(deadline);
  Generate();
  return outcome_;
}

}  // namespace dyad::pvrnn
