// nrl_network.hpp (internal): NRL's PV-RNN as NRL's code computes it (LayerPvrnn, NetworkPvrnn,
// Utils of github.com/oist-cnru/NRL, commit 42395a2), shared by the NRL modes of error regression
// (nrl_regression.cpp) and training (nrl_trainer.cpp); docs/pvrnn.md, "The NRL mode".
//
// - `Layer::Forward` is LayerPvrnn::t_forward / e_forward (the free-running prior path beside the
//   posterior, float, NRL's order of operations); `Layer::Backward` is t_backward / e_backward,
//   NRL's gradient as written (bug 3 of docs/pvrnn.md), with the weight gradients when asked.
// - `ForwardPass` and `BackwardPass` are NetworkPvrnn's loops over steps and layers for one
//   sequence; the caller owns the trajectories and A.
// - `NrlInitialModel` replays NRL's initial weights and A (Eigen 3.4's MatrixXf::Random over
//   glibc's rand() in its default state, NRL's construction order and Kaiming bounds).
// - `AdamUpdate` is Utils::adam (double arithmetic, float storage).
// Allocates freely: it is NRL's code shape, not dyad's fast path.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "dyad/pvrnn/model.hpp"

namespace dyad::pvrnn::nrl {

using VecF = Eigen::VectorXf;
using ArrF = Eigen::ArrayXf;
inline constexpr float kNonZero = 1.0e-20f;  // NRL's NON_ZERO (includes.h)

void TanH(VecF* v);
void Softmax(VecF* x);  // Utils::softmax: no max shift
// NRL's get_kld: float terms, summed in double per unit into a float.
float Kld(const ArrF& up, const ArrF& sp, const ArrF& uq, const ArrF& sq);

// Utils::adam on one vector or matrix: m, v, bias correction and step in double, stored as float;
// the gradient is zeroed after (NRL zeroes it right after the step).
template <typename T>
void AdamUpdate(T* p, T* g, T* m, T* v, int64_t step, float alpha, float beta1, float beta2, float eps) {
  const double c1 = 1.0 - std::pow(static_cast<double>(beta1), static_cast<double>(step));
  const double c2 = 1.0 - std::pow(static_cast<double>(beta2), static_cast<double>(step));
  float *pd = p->data(), *gd = g->data(), *md = m->data(), *vd = v->data();
  for (Eigen::Index i = 0; i < p->size(); ++i) {
    const float gi = gd[i];
    md[i] = static_cast<float>(beta1 * md[i] + (1.0 - beta1) * gi);
    vd[i] = static_cast<float>(beta2 * vd[i] + (1.0 - beta2) * (gi * gi));
    const float m_hat = static_cast<float>(md[i] / c1);
    const float v_hat = static_cast<float>(vd[i] / c2);
    pd[i] = static_cast<float>(pd[i] - (alpha * m_hat) / (std::pow(v_hat, 0.5) + eps));
  }
  g->setZero();
}

// Dataset's softmax code: r reference points i / (r - 1) summed in float (Dataset's constructor);
// one DOF value's code (float, no clamping; with v + NON_ZERO as encodeSoftmax does for ER's
// window, without as Dataset::softmax does for the training data).
std::vector<float> ReferencePoints(int r);
VecF EncodeValue(float value, float jmin, float jrange, const std::vector<float>& ref, float sigma, bool non_zero);

// NRL's N(0,1) (Utils::randN): std::normal_distribution<float> over std::default_random_engine,
// or 0 when off.
class Noise {
 public:
  void Reset(bool on, uint64_t seed);
  void Draw(VecF* n);

 private:
  bool on_ = false;
  std::default_random_engine engine_;
  std::normal_distribution<float> n01_{0.0f, 1.0f};
};

// One layer's states of one pass: index 0 is the start, 1..T the steps.
struct Trajectory {
  std::vector<VecF> hp, dp, up, lp, sp, np, hq, dq, uq, lq, sq, nq, zq;
  std::vector<float> kld;
  void Reset(int steps, int d, int z);  // T + 1 zero entries
};

struct Layer;
// The weight gradients of one layer (LayerPvrnn's g_W*, g_B*), shaped like its weights.
struct LayerGradients {
  Eigen::MatrixXf Wdh, Wzh, Wdh_bottom, Wdh_top, Wdup, Wdlp, Wduq, Wdlq;
  VecF Bh, Bup, Blp, Buq, Blq;
  explicit LayerGradients(const Layer& l);
  LayerGradients() = default;
};

struct Layer {
  int d = 0, z = 0, z_offset = 0;
  bool bottom = true, top = true;
  float eps = 1, one_sub_eps = 0, eps_bottom = 0, eps_top = 0, w_div_z = 0;
  Eigen::MatrixXf Wdh, Wzh, Wdh_bottom, Wdh_top, Wdup, Wdlp, Wduq, Wdlq;
  Eigen::MatrixXf Wdh_bottom_transpose, Wdh_top_transpose;  // NRL keeps explicit copies
  VecF Bh, Bup, Blp, Buq, Blq;
  // The neighbours' previous d (prior, posterior), set by the network before each step.
  VecF dp_bottom_prev, dq_bottom_prev, dp_top_prev, dq_top_prev;
  // Backward state (LayerPvrnn's context).
  VecF g_h_next, g_hq_bottom_next, g_hq_top_next, g_dqloss;
  Eigen::RowVectorXf g_up_next, g_uq_next, g_lp_next, g_lq_next;

  // Step t (1..T) of the prior path and the posterior with A (au, al) of that step.
  void Forward(Trajectory* tr, int t, const VecF& au, const VecF& al, Noise* noise) const;
  void InitBackward();
  // Step t (T..1): A's gradient of that step into g_au, g_al; the weight gradients added to
  // `grads` unless null.
  void Backward(const Trajectory& tr, int t, int steps, VecF* g_au, VecF* g_al, LayerGradients* grads);
  void RefreshTransposes();
};

// The layers of a model's weights (meta-prior w per layer, total_z for NRL's w / z_sum).
std::vector<Layer> MakeLayers(const ModelSpec& spec, const Weights<float>& w, const std::vector<float>& meta_prior);
// NetworkPvrnn's output weights per DOF.
void OutputWeights(const ModelSpec& spec, const Weights<float>& w, std::vector<Eigen::MatrixXf>* w_out, std::vector<VecF>* b_out);

// A per layer: a[k] points to that layer's A of steps 0..T-1.
using AView = std::vector<const std::vector<VecF>*>;
using Outputs = std::vector<std::vector<VecF>>;  // [step][dof]

// NetworkPvrnn::t_forward / e_forward: steps 1..T from the trajectories' entries 0; x[t-1][dof].
void ForwardPass(const std::vector<Layer*>& layers, std::vector<Trajectory*>& tr, int steps, const AView& au, const AView& al,
                 Noise* noise, const std::vector<Eigen::MatrixXf>& w_out, const std::vector<VecF>& b_out, Outputs* x);

struct OutputGradients {
  std::vector<Eigen::MatrixXf> w;
  std::vector<VecF> b;
};
// NetworkPvrnn::t_backward / e_backward for one sequence: rec += the reconstruction (float, steps
// T..1), kld[k] = the layer's KL summed over the steps; g_au[k][t-1], g_al[k][t-1] = A's gradient;
// weight gradients added to grads[k] and out (both null in error regression). w_out_t: the output
// weights' transposes NRL uses (in error regression its stale random ones).
struct BackwardSinks {
  std::vector<std::vector<VecF>*> g_au, g_al;
  std::vector<LayerGradients>* grads = nullptr;
  OutputGradients* out = nullptr;
};
void BackwardPass(const std::vector<Layer*>& layers, const std::vector<Trajectory*>& tr, int steps, const Outputs& x,
                  const Outputs& y, const std::vector<Eigen::MatrixXf>& w_out_t, float rec_coef, float* rec,
                  std::vector<float>* kld, const BackwardSinks& sinks);

// NRL's initial model for this shape (weights and A of `primitives` x `steps`), as NRL's
// constructors draw it in a fresh process (docs/pvrnn.md, "The NRL mode", Training).
Model NrlInitialModel(const ModelSpec& spec, int steps, int primitives);

}  // namespace dyad::pvrnn::nrl
