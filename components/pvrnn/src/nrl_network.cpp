#include "nrl_network.hpp"

#include <string>

namespace dyad::pvrnn::nrl {

namespace {
constexpr int kGlibcRandMax = 2147483647;  // RAND_MAX of the C library NRL ran with

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
  // Eigen 3.4's MatrixXf::Random coefficient: -1 + 2 rand() / RAND_MAX in float.
  float Uniform() { return -1.0f + (2.0f * static_cast<float>(Next())) / static_cast<float>(kGlibcRandMax); }

 private:
  uint32_t ring_[34];
  int pos_ = 0;  // index of r[i-34], overwritten by r[i]
};

// Utils::kaiming_uniform_initialization(d0, d1, nl) (column-major) into a group of `w`.
void KaimingMatrix(GlibcRand* rand, Weights<double>* w, const std::string& name, int d0, int d1, bool tanh_gain) {
  const float gain = tanh_gain ? static_cast<float>(5.0 / 3.0) : 1.0f;
  const float stdev = gain / std::sqrt(static_cast<float>(d1));
  const float bound = static_cast<float>(std::sqrt(3.0) * stdev);
  Eigen::MatrixXf m(d0, d1);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = rand->Uniform() * bound;
  w->Group(*w->layout().FindGroup(name)) = m.cast<double>();
}

// Utils::kaiming_uniform_initialization(n): U(-1, 1) / sqrt(n).
VecF KaimingVector(GlibcRand* rand, int n) {
  const float bound = static_cast<float>(1.0 / std::sqrt(static_cast<float>(n)));
  VecF v(n);
  for (Eigen::Index i = 0; i < n; ++i) v[i] = rand->Uniform() * bound;
  return v;
}

Eigen::MatrixXf GroupOf(const Weights<float>& w, const std::string& name) {
  const ParameterGroup* g = w.layout().FindGroup(name);
  return g == nullptr ? Eigen::MatrixXf() : Eigen::MatrixXf(w.Group(*g));
}
}  // namespace

void TanH(VecF* v) {
  for (Eigen::Index i = 0; i < v->size(); ++i) (*v)[i] = std::tanh((*v)[i]);
}

void Softmax(VecF* x) {
  float accum = 0;
  for (Eigen::Index i = 0; i < x->size(); ++i) {
    (*x)[i] = std::exp((*x)[i]);
    accum += (*x)[i];
  }
  *x /= accum;
}

float Kld(const ArrF& up, const ArrF& sp, const ArrF& uq, const ArrF& sq) {
  float kld = 0;
  for (Eigen::Index i = 0; i < up.size(); ++i) {
    const float diff = uq[i] - up[i];
    kld = static_cast<float>(kld + (-std::log(sq[i] / sp[i]) + (diff * diff + sq[i] * sq[i]) / (2.0 * (sp[i] * sp[i])) - 0.5));
  }
  return kld;
}

std::vector<float> ReferencePoints(int r) {
  const float lin_step = static_cast<float>(1.0 / static_cast<float>((r - 1) * 1.0));
  std::vector<float> ref;
  for (float ri = 0; static_cast<int>(ref.size()) < r; ri += lin_step) ref.push_back(ri);
  return ref;
}

VecF EncodeValue(float value, float jmin, float jrange, const std::vector<float>& ref, float sigma, bool non_zero) {
  const float sigma2 = sigma * sigma;
  float v = (value - jmin) / jrange;
  if (non_zero) v += kNonZero;
  VecF enc = VecF::Zero(static_cast<Eigen::Index>(ref.size()));
  float normalization = 0;
  for (size_t r = 0; r < ref.size(); ++r) {
    const float e = static_cast<float>(std::exp(-(std::pow(ref[r] - v, 2.0)) / sigma2));
    enc[static_cast<Eigen::Index>(r)] = e;
    normalization += e;
  }
  enc /= normalization;
  return enc;
}

void Noise::Reset(bool on, uint64_t seed) {
  on_ = on;
  engine_.seed(static_cast<std::default_random_engine::result_type>(seed));
  n01_.reset();
}

void Noise::Draw(VecF* n) {
  if (!on_) return;
  for (Eigen::Index i = 0; i < n->size(); ++i) (*n)[i] = n01_(engine_);
}

void Trajectory::Reset(int steps, int d, int z) {
  for (auto* v : {&hp, &dp, &hq, &dq}) v->assign(steps + 1, VecF::Zero(d));
  for (auto* v : {&up, &lp, &sp, &np, &uq, &lq, &sq, &nq, &zq}) v->assign(steps + 1, VecF::Zero(z));
  kld.assign(steps + 1, 0.0f);
}

LayerGradients::LayerGradients(const Layer& l) {
  for (auto [g, w] : {std::pair{&Wdh, &l.Wdh},
                      {&Wzh, &l.Wzh},
                      {&Wdh_bottom, &l.Wdh_bottom},
                      {&Wdh_top, &l.Wdh_top},
                      {&Wdup, &l.Wdup},
                      {&Wdlp, &l.Wdlp},
                      {&Wduq, &l.Wduq},
                      {&Wdlq, &l.Wdlq}})
    *g = Eigen::MatrixXf::Zero(w->rows(), w->cols());
  for (auto [g, b] : {std::pair{&Bh, &l.Bh}, {&Bup, &l.Bup}, {&Blp, &l.Blp}, {&Buq, &l.Buq}, {&Blq, &l.Blq}})
    *g = VecF::Zero(b->size());
}

// LayerPvrnn::t_forward / e_forward: step t (1..T) of the prior path and the posterior.
void Layer::Forward(Trajectory* tr, int t, const VecF& au, const VecF& al, Noise* noise) const {
  VecF h_p = tr->hp[t - 1];
  const VecF& d_p = tr->dp[t - 1];
  VecF u_p = Wdup * d_p + Bup;
  TanH(&u_p);
  const VecF l_p = Wdlp * d_p + Blp;
  const VecF s_p = l_p.array().exp();
  VecF n_p = VecF::Zero(z);
  noise->Draw(&n_p);
  const VecF z_p = (u_p.array() + s_p.array() * n_p.array()).matrix();
  h_p = one_sub_eps * h_p + eps * (Wdh * d_p + Wzh * z_p + Bh);

  VecF h_q = tr->hq[t - 1];
  const VecF& d_q = tr->dq[t - 1];
  VecF u_q = Wduq * d_q + Buq + au;
  TanH(&u_q);
  const VecF l_q = Wdlq * d_q + Blq + al;
  const VecF s_q = l_q.array().exp();
  VecF n_q = VecF::Zero(z);
  noise->Draw(&n_q);
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
  tr->hp[t] = h_p;
  tr->dp[t] = h_p;
  TanH(&tr->dp[t]);
  tr->hq[t] = h_q;
  tr->dq[t] = h_q;
  TanH(&tr->dq[t]);
  tr->up[t] = u_p, tr->lp[t] = l_p, tr->sp[t] = s_p, tr->np[t] = n_p;
  tr->uq[t] = u_q, tr->lq[t] = l_q, tr->sq[t] = s_q, tr->nq[t] = n_q, tr->zq[t] = z_q;
  tr->kld[t] = Kld(u_p.array(), s_p.array(), u_q.array(), s_q.array());
}

void Layer::InitBackward() {
  g_h_next = VecF::Zero(d);
  for (auto* g : {&g_up_next, &g_uq_next, &g_lp_next, &g_lq_next}) *g = Eigen::RowVectorXf::Zero(z);
}

// LayerPvrnn::t_backward / e_backward: step t (T..1), NRL's gradient as written.
void Layer::Backward(const Trajectory& tr, int t, int steps, VecF* g_au, VecF* g_al, LayerGradients* grads) {
  const ArrF up_next = t < steps ? ArrF(tr.up[t + 1]) : ArrF::Zero(z);
  const ArrF uq_next = t < steps ? ArrF(tr.uq[t + 1]) : ArrF::Zero(z);
  const ArrF u_p = tr.up[t], s_p = tr.sp[t], s_q = tr.sq[t], u_q = tr.uq[t], n_q = tr.nq[t], d_q = tr.dq[t];
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
  *g_au = (g_uq * (1.0f - uq_pow_2)).matrix();
  *g_al = g_lq.matrix();
  if (grads != nullptr) {  // LayerPvrnn::t_backward's parameter gradients
    const Eigen::RowVectorXf zq = tr.zq[t].transpose(), dp_prev = tr.dp[t - 1].transpose(), dq_prev = tr.dq[t - 1].transpose();
    grads->Wdh += eps * g_h * dq_prev;
    grads->Bh += eps * g_h;
    if (!bottom) grads->Wdh_bottom += eps * g_h * dq_bottom_prev.transpose();
    if (!top) grads->Wdh_top += eps * g_h * dq_top_prev.transpose();
    grads->Wzh += eps * g_h * zq;
    grads->Wduq += *g_au * dq_prev;
    grads->Buq += *g_au;
    grads->Wdlq += g_lq.matrix() * dq_prev;
    grads->Blq += g_lq.matrix();
    const VecF g_uptanh_t = (g_up * (1.0f - u_p.square())).matrix();
    grads->Wdup += g_uptanh_t * dp_prev;
    grads->Bup += g_uptanh_t;
    grads->Wdlp += g_lp.matrix() * dp_prev;
    grads->Blp += g_lp.matrix();
  }
  g_h_next = g_h;
  g_up_next = g_up.matrix().transpose();
  g_uq_next = g_uq.matrix().transpose();
  g_lp_next = g_lp.matrix().transpose();
  g_lq_next = g_lq.matrix().transpose();
}

void Layer::RefreshTransposes() {
  Wdh_bottom_transpose = Wdh_bottom.transpose();
  Wdh_top_transpose = Wdh_top.transpose();
}

std::vector<Layer> MakeLayers(const ModelSpec& spec, const Weights<float>& w, const std::vector<float>& meta_prior) {
  const NetworkLayout& l = w.layout();
  const int K = l.num_layers();
  std::vector<Layer> layers(K);
  for (int k = 0; k < K; ++k) {
    Layer& y = layers[k];
    const std::string L = "L" + std::to_string(k) + ".";
    y.d = spec.layers[k].d;
    y.z = spec.layers[k].z;
    y.bottom = k == 0;
    y.top = k + 1 == K;
    y.eps = static_cast<float>(1.0 / spec.layers[k].tau);
    y.one_sub_eps = static_cast<float>(1.0 - y.eps);
    if (!y.bottom) y.eps_bottom = static_cast<float>(1.0 / spec.layers[k - 1].tau);
    if (!y.top) y.eps_top = static_cast<float>(1.0 / spec.layers[k + 1].tau);
    y.w_div_z = static_cast<float>(meta_prior[k] / (static_cast<float>(l.total_z()) * 1.0));
    y.Wdh = GroupOf(w, L + "W_dh"), y.Wzh = GroupOf(w, L + "W_zh");
    y.Wdh_bottom = GroupOf(w, L + "W_below"), y.Wdh_top = GroupOf(w, L + "W_above");
    y.Wdup = GroupOf(w, L + "W_mu_p"), y.Wdlp = GroupOf(w, L + "W_ls_p");
    y.Wduq = GroupOf(w, L + "W_mu_q"), y.Wdlq = GroupOf(w, L + "W_ls_q");
    y.Bh = GroupOf(w, L + "b_h"), y.Bup = GroupOf(w, L + "b_mu_p"), y.Blp = GroupOf(w, L + "b_ls_p");
    y.Buq = GroupOf(w, L + "b_mu_q"), y.Blq = GroupOf(w, L + "b_ls_q");
    y.z_offset = l.z_offset(k);
    y.RefreshTransposes();
  }
  return layers;
}

void OutputWeights(const ModelSpec& spec, const Weights<float>& w, std::vector<Eigen::MatrixXf>* w_out,
                   std::vector<VecF>* b_out) {
  w_out->clear();
  b_out->clear();
  for (int dof = 0; dof < spec.num_dofs(); ++dof) {
    w_out->push_back(GroupOf(w, "out.W_x" + std::to_string(dof)));
    b_out->push_back(GroupOf(w, "out.b_x" + std::to_string(dof)));
  }
}

void ForwardPass(const std::vector<Layer*>& layers, std::vector<Trajectory*>& tr, int steps, const AView& au, const AView& al,
                 Noise* noise, const std::vector<Eigen::MatrixXf>& w_out, const std::vector<VecF>& b_out, Outputs* x) {
  const int K = static_cast<int>(layers.size());
  x->assign(steps, {});
  for (int t = 1; t <= steps; ++t) {
    for (int k = 0; k < K; ++k) {
      Layer& y = *layers[k];
      if (k > 0) y.dp_bottom_prev = tr[k - 1]->dp[t - 1], y.dq_bottom_prev = tr[k - 1]->dq[t - 1];
      if (k + 1 < K) y.dp_top_prev = tr[k + 1]->dp[t - 1], y.dq_top_prev = tr[k + 1]->dq[t - 1];
      y.Forward(tr[k], t, (*au[k])[t - 1], (*al[k])[t - 1], noise);
    }
    const VecF dq0 = tr[0]->dq[t];
    for (size_t o = 0; o < w_out.size(); ++o) {
      VecF xo = w_out[o] * dq0 + b_out[o];
      Softmax(&xo);
      (*x)[t - 1].push_back(xo);
    }
  }
}

void BackwardPass(const std::vector<Layer*>& layers, const std::vector<Trajectory*>& tr, int steps, const Outputs& x,
                  const Outputs& y, const std::vector<Eigen::MatrixXf>& w_out_t, float rec_coef, float* rec,
                  std::vector<float>* kld, const BackwardSinks& sinks) {
  const int K = static_cast<int>(layers.size());
  std::vector<VecF> g_h(K), g_h_next(K);
  kld->assign(K, 0.0f);
  for (int k = 0; k < K; ++k) {
    g_h_next[k] = VecF::Zero(layers[k]->d);
    layers[k]->InitBackward();
  }
  for (int t = steps; t > 0; --t) {
    VecF g_dqloss = VecF::Zero(layers[0]->d);
    const Eigen::RowVectorXf l0_dq = tr[0]->dq[t].transpose();
    for (size_t o = 0; o < w_out_t.size(); ++o) {
      const ArrF xo = x[t - 1][o], target = y[t - 1][o];
      const ArrF yx = (target / xo) + kNonZero;
      const VecF rec_t = target * yx.log();
      const VecF gx = rec_coef * (xo - target);
      g_dqloss += w_out_t[o] * gx;
      if (sinks.out != nullptr) {
        sinks.out->w[o] += gx * l0_dq;
        sinks.out->b[o] += gx;
      }
      *rec += rec_t.sum();
    }
    for (int k = 0; k < K; ++k) {
      Layer& l = *layers[k];
      if (k > 0) l.g_hq_bottom_next = g_h_next[k - 1], l.dq_bottom_prev = tr[k - 1]->dq[t - 1];
      else l.g_dqloss = g_dqloss;
      if (k + 1 < K) l.g_hq_top_next = g_h_next[k + 1], l.dq_top_prev = tr[k + 1]->dq[t - 1];
      l.Backward(*tr[k], t, steps, &(*sinks.g_au[k])[t - 1], &(*sinks.g_al[k])[t - 1],
                 sinks.grads != nullptr ? &(*sinks.grads)[k] : nullptr);
      g_h[k] = l.g_h_next;
      (*kld)[k] += tr[k]->kld[t];
    }
    g_h_next = g_h;
  }
}

Model NrlInitialModel(const ModelSpec& spec, int steps, int primitives) {
  Model m = Model::Initialize(spec, steps, primitives, 0);  // the layout; every value is replaced
  GlibcRand rand;
  const int K = spec.num_layers();
  for (int k = 0; k < K; ++k) {  // LayerPvrnn's constructor
    const std::string L = "L" + std::to_string(k) + ".";
    const int d = spec.layers[k].d, z = spec.layers[k].z;
    auto vec = [&](const std::string& name, int n) {
      m.weights.Group(*m.weights.layout().FindGroup(L + name)) = KaimingVector(&rand, n).cast<double>();
    };
    KaimingMatrix(&rand, &m.weights, L + "W_dh", d, d, false);
    vec("b_h", d);
    KaimingMatrix(&rand, &m.weights, L + "W_zh", d, z, false);
    if (k > 0) KaimingMatrix(&rand, &m.weights, L + "W_below", d, spec.layers[k - 1].d, false);
    if (k + 1 < K) KaimingMatrix(&rand, &m.weights, L + "W_above", d, spec.layers[k + 1].d, false);
    KaimingMatrix(&rand, &m.weights, L + "W_mu_p", z, d, true);
    KaimingMatrix(&rand, &m.weights, L + "W_ls_p", z, d, false);
    KaimingMatrix(&rand, &m.weights, L + "W_mu_q", z, d, true);
    KaimingMatrix(&rand, &m.weights, L + "W_ls_q", z, d, false);
    for (const char* b : {"b_mu_p", "b_ls_p", "b_mu_q", "b_ls_q"}) vec(b, z);
    const int off = m.weights.layout().z_offset(k);
    for (int p = 0; p < primitives; ++p)
      for (int t = 0; t < steps; ++t) {
        const int c = m.adaptive.Column(t, p);
        m.adaptive.mu().col(c).segment(off, z) = KaimingVector(&rand, z).cast<double>();
        m.adaptive.log_sigma().col(c).segment(off, z) = KaimingVector(&rand, z).cast<double>();
      }
  }
  const int d0 = spec.layers[0].d;
  for (int o = 0; o < spec.num_dofs(); ++o) {  // NetworkPvrnn's constructor
    const int n = spec.output.UnitsFor(o);
    KaimingMatrix(&rand, &m.weights, "out.W_x" + std::to_string(o), n, d0, false);
    m.weights.Group(*m.weights.layout().FindGroup("out.b_x" + std::to_string(o))) = KaimingVector(&rand, n).cast<double>();
  }
  return m;
}

}  // namespace dyad::pvrnn::nrl
