#include "dyad/pvrnn/nrl_regression.hpp"

#include <cmath>
#include <cstdint>
#include <limits>

#include "dyad/pvrnn/error_regression.hpp"

namespace dyad::pvrnn {

namespace {
constexpr float kNonZero = 1.0e-20f;       // NRL's NON_ZERO (includes.h)
constexpr int kGlibcRandMax = 2147483647;  // RAND_MAX of the C library NRL ran with
using VecF = Eigen::VectorXf;
using ArrF = Eigen::ArrayXf;
using Trajectory = std::vector<VecF>;  // W + 1 entries; [0] is the start (NRL pushes it first)

void TanH(VecF* v) {
  for (Eigen::Index i = 0; i < v->size(); ++i) (*v)[i] = std::tanh((*v)[i]);
}

// NRL's Utils::adam on one vector: m, v, bias correction and step in double, stored as float.
void AdamUpdate(VecF* p, VecF* g, VecF* m, VecF* v, int64_t step, float alpha, float beta1, float beta2, float eps) {
  const double c1 = 1.0 - std::pow(static_cast<double>(beta1), static_cast<double>(step));
  const double c2 = 1.0 - std::pow(static_cast<double>(beta2), static_cast<double>(step));
  for (Eigen::Index i = 0; i < p->size(); ++i) {
    const float gi = (*g)[i];
    (*m)[i] = static_cast<float>(beta1 * (*m)[i] + (1.0 - beta1) * gi);
    (*v)[i] = static_cast<float>(beta2 * (*v)[i] + (1.0 - beta2) * (gi * gi));
    const float m_hat = static_cast<float>((*m)[i] / c1);
    const float v_hat = static_cast<float>((*v)[i] / c2);
    (*p)[i] = static_cast<float>((*p)[i] - (alpha * m_hat) / (std::pow(v_hat, 0.5) + eps));
  }
  g->setZero();
}

// NRL's get_kld: float terms, summed in double per unit into a float.
float Kld(const ArrF& up, const ArrF& sp, const ArrF& uq, const ArrF& sq) {
  float kld = 0;
  for (Eigen::Index i = 0; i < up.size(); ++i) {
    const float diff = uq[i] - up[i];
    kld = static_cast<float>(kld + (-std::log(sq[i] / sp[i]) + (diff * diff + sq[i] * sq[i]) / (2.0 * (sp[i] * sp[i])) - 0.5));
  }
  return kld;
}

// glibc's rand() after srand(1) (its default state): the TYPE_3 additive feedback generator,
// written out so that NRL's draws are replayed without touching the process's rand().
class GlibcRand {
 public:
  GlibcRand() {
    int32_t r[344];
    r[0] = 1;
    for (int i = 1; i < 31; ++i) {
      const long long h = (16807LL * r[i - 1]) % 2147483647;
      r[i] = static_cast<int32_t>(h < 0 ? h + 2147483647 : h);
    }
    for (int i = 31; i < 34; ++i) r[i] = r[i - 31];
    for (int i = 34; i < 344; ++i)
      r[i] = static_cast<int32_t>(static_cast<uint32_t>(r[i - 31]) + static_cast<uint32_t>(r[i - 3]));
    for (int i = 0; i < 34; ++i) ring_[i] = static_cast<uint32_t>(r[310 + i]);
  }
  int Next() {
    const uint32_t v = ring_[(pos_ + 3) % 34] + ring_[(pos_ + 31) % 34];  // r[i-31] + r[i-3]
    ring_[pos_] = v;
    pos_ = (pos_ + 1) % 34;
    return static_cast<int>(v >> 1);
  }

 private:
  uint32_t ring_[34];
  int pos_ = 0;  // index of r[i-34], overwritten by r[i]
};

// NRL bug: NetworkPvrnn::load reads the output weights Wdo but not their transposes
// Wdo_transpose (set from the random initial Wdo in the constructor, NetworkPvrnn.cpp:133-137, and
// refreshed only by a training step, :345), and e_backward's output gradient uses the transposes
// (:716): so a loaded model's ER gradient goes back through NRL's random initial output weights.
// They are replayed here: Utils::kaiming_uniform_initialization (Eigen 3.4's
// MatrixXf::Random: -1 + 2 rand() / RAND_MAX in float, column-major, times the bound) in the
// construction order of NetworkPvrnn and LayerPvrnn (per layer: Wdh, Bh, Wzh, Wdh_bottom,
// Wdh_top, Wdup, Wdlp, Wduq, Wdlq, Bup, Blp, Buq, Blq, then au, al per primitive and step; then
// per output Wdo, Bo), from glibc's rand() in its default state (NRL never calls srand).
std::vector<Eigen::MatrixXf> NrlInitialOutputTransposes(const ModelSpec& spec, int primitives, int steps) {
  GlibcRand rand;
  auto draw = [&rand](int64_t n) {
    for (int64_t i = 0; i < n; ++i) rand.Next();
  };
  const int K = spec.num_layers();
  for (int k = 0; k < K; ++k) {
    const int64_t d = spec.layers[k].d, z = spec.layers[k].z;
    const int64_t below = k > 0 ? spec.layers[k - 1].d : 0, above = k + 1 < K ? spec.layers[k + 1].d : 0;
    draw(d * d + d + d * z + d * below + d * above + 4 * z * d + 4 * z + 2 * z * primitives * steps);
  }
  const int d0 = spec.layers[0].d;
  const float bound = static_cast<float>(std::sqrt(3.0) * (1.0f / std::sqrt(static_cast<float>(d0))));
  std::vector<Eigen::MatrixXf> out;
  for (int o = 0; o < spec.num_dofs(); ++o) {
    const int n = spec.output.UnitsFor(o);
    Eigen::MatrixXf w(n, d0);
    for (Eigen::Index i = 0; i < w.size(); ++i)
      w.data()[i] = (-1.0f + (2.0f * static_cast<float>(rand.Next())) / static_cast<float>(kGlibcRandMax)) * bound;
    out.push_back(w.transpose());
    draw(n);  // Bo
  }
  return out;
}

Eigen::MatrixXf GroupOf(const Weights<float>& w, const std::string& name) {
  const ParameterGroup* g = w.layout().FindGroup(name);
  return g == nullptr ? Eigen::MatrixXf() : Eigen::MatrixXf(w.Group(*g));
}
}  // namespace

struct NrlRegression::Layer {
  int d = 0, z = 0, z_offset = 0;
  bool bottom = true, top = true;
  float eps = 1, one_sub_eps = 0, eps_bottom = 0, eps_top = 0, w_div_z = 0;
  Eigen::MatrixXf Wdh, Wzh, Wdh_bottom, Wdh_top, Wdup, Wdlp, Wduq, Wdlq;
  Eigen::MatrixXf Wdh_bottom_transpose, Wdh_top_transpose;  // NRL keeps explicit copies
  VecF Bh, Bup, Blp, Buq, Blq;
  // Window: A, its kept copy, gradients, Adam moments (W slots each).
  std::vector<VecF> au, al, au_copy, al_copy, g_au, g_al, m_au, m_al, v_au, v_al;
  VecF hq_tzero, dq_tzero, hq_opt, dq_opt;
  VecF hp_gen, dp_gen;
  int gen_time = 0;
  // Trajectories of the last forward pass (W + 1 entries).
  Trajectory hp, dp, up, lp, sp, np, hq, dq, uq, lq, sq, nq;
  std::vector<float> kld;
  // Neighbours' previous d (prior, posterior) and backward state.
  VecF dp_bottom_prev, dq_bottom_prev, dp_top_prev, dq_top_prev;
  VecF g_h_next, g_hq_bottom_next, g_hq_top_next, g_dqloss;
  Eigen::RowVectorXf g_up_next, g_uq_next, g_lp_next, g_lq_next;

  void ResetState(int window);
  void Generate(NrlRegression* er);
  void Forward(int t, NrlRegression* er);
  void Backward(int t, int window);
};

void NrlRegression::Layer::ResetState(int window) {
  for (auto* v : {&au, &al, &au_copy, &al_copy, &g_au, &g_al, &m_au, &m_al, &v_au, &v_al}) v->assign(window, VecF::Zero(z));
  for (auto* v : {&hq_tzero, &dq_tzero, &hq_opt, &dq_opt, &hp_gen, &dp_gen}) *v = VecF::Zero(d);
  gen_time = 0;
  for (auto* v : {&hp, &dp, &hq, &dq}) v->assign(window + 1, VecF::Zero(d));
  for (auto* v : {&up, &lp, &sp, &np, &uq, &lq, &sq, &nq}) v->assign(window + 1, VecF::Zero(z));
  kld.assign(window + 1, 0.0f);
}

// LayerPvrnn::e_forward: step t (1..W) of the prior path and the posterior.
void NrlRegression::Layer::Forward(int t, NrlRegression* er) {
  VecF h_p = hp[t - 1];
  const VecF& d_p = dp[t - 1];
  VecF u_p = Wdup * d_p + Bup;
  TanH(&u_p);
  const VecF l_p = Wdlp * d_p + Blp;
  const VecF s_p = l_p.array().exp();
  VecF n_p = VecF::Zero(z);
  er->Draw(&n_p);
  const VecF z_p = (u_p.array() + s_p.array() * n_p.array()).matrix();
  h_p = one_sub_eps * h_p + eps * (Wdh * d_p + Wzh * z_p + Bh);

  VecF h_q = hq[t - 1];
  const VecF& d_q = dq[t - 1];
  VecF u_q = Wduq * d_q + Buq + au[t - 1];
  TanH(&u_q);
  const VecF l_q = Wdlq * d_q + Blq + al[t - 1];
  const VecF s_q = l_q.array().exp();
  VecF n_q = VecF::Zero(z);
  er->Draw(&n_q);
  const VecF z_q = (u_q.array() + s_q.array() * n_q.array()).matrix();
  h_q = one_sub_eps * h_q + eps * (Wdh * d_q + Wzh * z_q + Bh);
  if (!bottom) {
    h_p += eps * Wdh_bottom * dp_bottom_prev;
    h_q += eps * Wdh_bottom * dq_bottom_prev;
  }
  if (!top) {
    h_p += eps * Wdh_top * dp_top_prev;
    h_q += eps * Wdh_top * dq_top_prev;
  }
  hp[t] = h_p;
  dp[t] = h_p;
  TanH(&dp[t]);
  hq[t] = h_q;
  dq[t] = h_q;
  TanH(&dq[t]);
  up[t] = u_p, lp[t] = l_p, sp[t] = s_p, np[t] = n_p;
  uq[t] = u_q, lq[t] = l_q, sq[t] = s_q, nq[t] = n_q;
  kld[t] = Kld(u_p.array(), s_p.array(), u_q.array(), s_q.array());
}

// LayerPvrnn::e_backward: step t (W..1), NRL's gradient as written.
void NrlRegression::Layer::Backward(int t, int window) {
  const ArrF up_next = t < window ? ArrF(up[t + 1]) : ArrF::Zero(z);
  const ArrF uq_next = t < window ? ArrF(uq[t + 1]) : ArrF::Zero(z);
  const ArrF u_p = up[t], s_p = sp[t], s_q = sq[t], u_q = uq[t], n_q = nq[t], d_q = dq[t];
  const ArrF sp_pow_2 = s_p.square() + kNonZero;
  const ArrF sq_pow_2 = s_q.square();
  const ArrF uq_pow_2 = u_q.square();
  Eigen::RowVectorXf g_d = eps * g_h_next.transpose() * Wdh;
  if (!bottom) g_d += (VecF)(eps_bottom * g_hq_bottom_next.transpose() * Wdh_bottom_transpose).transpose();
  else g_d += g_dqloss.transpose();
  if (!top) g_d += (VecF)(eps_top * g_hq_top_next.transpose() * Wdh_top_transpose).transpose();
  const Eigen::RowVectorXf g_uptanh = (g_up_next.array() * (1.0f - up_next.square().transpose())).matrix();
  const Eigen::RowVectorXf g_uqtanh = (g_uq_next.array() * (1.0f - uq_next.square().transpose())).matrix();
  g_d += g_uptanh * Wdup;
  g_d += g_uqtanh * Wduq;
  g_d += g_lp_next * Wdlp;
  g_d += g_lq_next * Wdlq;
  const VecF g_h = (g_d.transpose().array() * (1.0f - d_q.square()) + one_sub_eps * g_h_next.array()).matrix();
  const ArrF g_z = (eps * g_h.transpose() * Wzh).transpose().array();
  const ArrF g_up = w_div_z * ((u_p - u_q) / sp_pow_2);
  const ArrF g_lp = w_div_z * (1.0f - ((u_q - u_p).square() + sq_pow_2) / sp_pow_2);
  const ArrF g_uq = g_z + w_div_z * ((u_q - u_p) / sp_pow_2);
  const ArrF g_lq = g_z * s_q * n_q + w_div_z * (-1.0f + sq_pow_2 / sp_pow_2);
  g_au[t - 1] = (g_uq * (1.0f - uq_pow_2)).matrix();
  g_al[t - 1] = g_lq.matrix();
  g_h_next = g_h;
  g_up_next = g_up.matrix().transpose();
  g_uq_next = g_uq.matrix().transpose();
  g_lp_next = g_lp.matrix().transpose();
  g_lq_next = g_lq.matrix().transpose();
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
      noise_(o.noise != NoiseMode::kOff) {
  const Weights<float> w = model.weights.Cast<float>();
  const AdaptiveVariables<float> a = model.adaptive.Cast<float>();
  const NetworkLayout& l = w.layout();
  const int K = l.num_layers();
  layers_.resize(K);
  for (int k = 0; k < K; ++k) {
    Layer& y = layers_[k];
    const std::string L = "L" + std::to_string(k) + ".";
    y.d = model.spec.layers[k].d;
    y.z = model.spec.layers[k].z;
    y.bottom = k == 0;
    y.top = k + 1 == K;
    y.eps = static_cast<float>(1.0 / model.spec.layers[k].tau);
    y.one_sub_eps = static_cast<float>(1.0 - y.eps);
    if (!y.bottom) y.eps_bottom = static_cast<float>(1.0 / model.spec.layers[k - 1].tau);
    if (!y.top) y.eps_top = static_cast<float>(1.0 / model.spec.layers[k + 1].tau);
    y.Wdh = GroupOf(w, L + "W_dh"), y.Wzh = GroupOf(w, L + "W_zh");
    y.Wdh_bottom = GroupOf(w, L + "W_below"), y.Wdh_top = GroupOf(w, L + "W_above");
    y.Wdup = GroupOf(w, L + "W_mu_p"), y.Wdlp = GroupOf(w, L + "W_ls_p");
    y.Wduq = GroupOf(w, L + "W_mu_q"), y.Wdlq = GroupOf(w, L + "W_ls_q");
    y.Bh = GroupOf(w, L + "b_h"), y.Bup = GroupOf(w, L + "b_mu_p"), y.Blp = GroupOf(w, L + "b_ls_p");
    y.Buq = GroupOf(w, L + "b_mu_q"), y.Blq = GroupOf(w, L + "b_ls_q");
    y.z_offset = l.z_offset(k);
    y.Wdh_bottom_transpose = y.Wdh_bottom.transpose();
    y.Wdh_top_transpose = y.Wdh_top.transpose();
    y.ResetState(window_);
  }
  for (int dof = 0; dof < model.spec.num_dofs(); ++dof) {
    w_out_.push_back(GroupOf(w, "out.W_x" + std::to_string(dof)));
    b_out_.push_back(GroupOf(w, "out.b_x" + std::to_string(dof)));
    const float lo = static_cast<float>(model.spec.output.dofs[dof].min);
    const float hi = static_cast<float>(model.spec.output.dofs[dof].max);
    jmin_.push_back(lo);
    jrange_.push_back(hi - lo);
    const int r = model.spec.output.UnitsFor(dof);
    const float lin_step = static_cast<float>(1.0 / static_cast<float>((r - 1) * 1.0));
    std::vector<float> ref;
    for (float ri = 0; static_cast<int>(ref.size()) < r; ri += lin_step) ref.push_back(ri);
    ref_.push_back(ref);
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

void NrlRegression::Draw(Eigen::VectorXf* n) {
  if (!noise_) return;
  for (Eigen::Index i = 0; i < n->size(); ++i) (*n)[i] = n01_(engine_);
}

void NrlRegression::Softmax(Eigen::VectorXf* x) const {
  float accum = 0;
  for (Eigen::Index i = 0; i < x->size(); ++i) {
    (*x)[i] = std::exp((*x)[i]);
    accum += (*x)[i];
  }
  *x /= accum;
}

float NrlRegression::Decode(const Eigen::VectorXf& x, int dof) const {
  float dec = 0;
  for (size_t r = 0; r < ref_[dof].size(); ++r) dec += ref_[dof][r] * x[static_cast<Eigen::Index>(r)];
  dec *= jrange_[dof];
  dec += jmin_[dof];
  return dec;
}

// Dataset::encodeSoftmax on the window's positions.
void NrlRegression::Encode(std::vector<std::vector<Eigen::VectorXf>>* y) const {
  const float sigma2 = sigma_ * sigma_;
  y->assign(buffer_.size(), {});
  for (size_t t = 0; t < buffer_.size(); ++t)
    for (size_t j = 0; j < ref_.size(); ++j) {
      const float v = ((buffer_[t][j] - jmin_[j]) / jrange_[j]) + kNonZero;
      VecF enc = VecF::Zero(static_cast<Eigen::Index>(ref_[j].size()));
      float normalization = 0;
      for (size_t r = 0; r < ref_[j].size(); ++r) {
        const float e = static_cast<float>(std::exp(-(std::pow(ref_[j][r] - v, 2.0)) / sigma2));
        enc[static_cast<Eigen::Index>(r)] = e;
        normalization += e;
      }
      enc /= normalization;
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
  TanH(&u);
  const VecF s = l.array().exp();
  VecF n = VecF::Zero(z);
  er->Draw(&n);
  const VecF zz = (u.array() + s.array() * n.array()).matrix();
  h = one_sub_eps * h + eps * (Wdh * d_prev + Wzh * zz + Bh);
  if (!bottom) h += eps * (Wdh_bottom * dp_bottom_prev);
  if (!top) h += eps * (Wdh_top * dp_top_prev);
  hp_gen = h;
  dp_gen = h;
  TanH(&dp_gen);
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
    Softmax(&x);
    intention_[static_cast<Eigen::Index>(o)] = Decode(x, static_cast<int>(o));
  }
}

// NetworkPvrnn::e_forward: prior path and posterior through the window from its start state.
void NrlRegression::Forward() {
  const int K = static_cast<int>(layers_.size());
  for (Layer& y : layers_) {
    y.hp[0] = y.hq[0] = y.hq_tzero;
    y.dp[0] = y.dq[0] = y.dq_tzero;
    for (auto* v : {&y.up, &y.lp, &y.sp, &y.np, &y.uq, &y.lq, &y.sq, &y.nq}) (*v)[0].setZero();
    y.kld[0] = 0;
  }
  x_.assign(window_, {});
  for (int t = 1; t <= window_; ++t) {
    for (int k = 0; k < K; ++k) {
      Layer& y = layers_[k];
      if (k > 0) y.dp_bottom_prev = layers_[k - 1].dp[t - 1], y.dq_bottom_prev = layers_[k - 1].dq[t - 1];
      if (k + 1 < K) y.dp_top_prev = layers_[k + 1].dp[t - 1], y.dq_top_prev = layers_[k + 1].dq[t - 1];
      y.Forward(t, this);
    }
    const VecF dq0 = layers_[0].dq[t];
    for (size_t o = 0; o < w_out_.size(); ++o) {
      VecF x = w_out_[o] * dq0 + b_out_[o];
      Softmax(&x);
      x_[t - 1].push_back(x);
    }
  }
}

// NetworkPvrnn::e_backward: the loss terms (float, summed backwards in time) and NRL's gradient.
void NrlRegression::Backward(const std::vector<std::vector<Eigen::VectorXf>>& y, float* rec, float* reg) {
  const int K = static_cast<int>(layers_.size());
  std::vector<VecF> g_h(K), g_h_next(K);
  std::vector<float> kld(K, 0.0f);
  for (int k = 0; k < K; ++k) {
    Layer& l = layers_[k];
    g_h_next[k] = VecF::Zero(l.d);
    l.g_h_next = VecF::Zero(l.d);
    for (auto* g : {&l.g_up_next, &l.g_uq_next, &l.g_lp_next, &l.g_lq_next}) *g = Eigen::RowVectorXf::Zero(l.z);
  }
  for (int t = window_; t > 0; --t) {
    VecF g_dqloss = VecF::Zero(layers_[0].d);
    for (size_t o = 0; o < w_out_.size(); ++o) {
      const ArrF x = x_[t - 1][o], target = y[t - 1][o];
      const ArrF yx = (target / x) + kNonZero;
      const VecF rec_t = target * yx.log();
      const VecF gx = rec_coef_ * (x - target);
      g_dqloss += w_out_t_[o] * gx;
      *rec += rec_t.sum();
    }
    for (int k = 0; k < K; ++k) {
      Layer& l = layers_[k];
      if (k > 0) l.g_hq_bottom_next = g_h_next[k - 1];
      else l.g_dqloss = g_dqloss;
      if (k + 1 < K) l.g_hq_top_next = g_h_next[k + 1];
      l.Backward(t, window_);
      g_h[k] = l.g_h_next;
      kld[k] += l.kld[t];
    }
    g_h_next = g_h;
  }
  for (int k = 0; k < K; ++k) {
    *reg += w_[k] * kld[k];
    outcome_kl_[k] = kld[k];
  }
}

void NrlRegression::AdamStep() {
  for (Layer& l : layers_)
    for (int t = 0; t < window_; ++t) {
      AdamUpdate(&l.au[t], &l.g_au[t], &l.m_au[t], &l.v_au[t], adam_step_, lr_, beta1_, beta2_, epsilon_);
      AdamUpdate(&l.al[t], &l.g_al[t], &l.m_al[t], &l.v_al[t], adam_step_, lr_, beta1_, beta2_, epsilon_);
    }
}

// LayerPvrnn::e_copyParam: the A after this iteration's Adam step, the states before it.
void NrlRegression::CopyParam() {
  for (Layer& l : layers_) {
    l.au_copy = l.au;
    l.al_copy = l.al;
    l.dp_gen = l.dq[window_];
    l.hp_gen = l.hq[window_];
    l.hq_opt = l.hq[1];
    l.dq_opt = l.dq[1];
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
  engine_.seed(static_cast<std::default_random_engine::result_type>(seed));
  n01_.reset();
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
