#include "dyad/pvrnn/nrl_trainer.hpp"

#include <string>

#include "nrl_network.hpp"

namespace dyad::pvrnn {

using nrl::VecF;

struct NrlTrainer::State {
  int steps = 0, primitives = 0;
  float rec_coef = 0, reg_coef = 0;
  std::vector<float> w;  // meta-prior per layer
  std::vector<nrl::Layer> layers;
  std::vector<nrl::LayerGradients> g, m, v;  // per layer
  std::vector<Eigen::MatrixXf> w_out, w_out_t;
  std::vector<VecF> b_out;
  nrl::OutputGradients g_out, m_out, v_out;
  // A and its gradient and Adam moments: [layer][primitive][step].
  using PerStep = std::vector<std::vector<std::vector<VecF>>>;
  PerStep au, al, g_au, g_al, m_au, m_al, v_au, v_al;
  std::vector<std::vector<nrl::Trajectory>> tr;  // [primitive][layer]
  std::vector<nrl::Outputs> x, y;                // [primitive][step][dof]
  nrl::Noise noise;

  std::vector<nrl::Layer*> LayerPointers() {
    std::vector<nrl::Layer*> p;
    for (nrl::Layer& l : layers) p.push_back(&l);
    return p;
  }
  std::vector<nrl::Trajectory*> TrajectoriesOf(int p) {
    std::vector<nrl::Trajectory*> t;
    for (nrl::Trajectory& l : tr[p]) t.push_back(&l);
    return t;
  }
};

namespace {

nrl::OutputGradients ZeroLike(const std::vector<Eigen::MatrixXf>& w, const std::vector<VecF>& b) {
  nrl::OutputGradients g;
  for (const auto& m : w) g.w.push_back(Eigen::MatrixXf::Zero(m.rows(), m.cols()));
  for (const auto& x : b) g.b.push_back(VecF::Zero(x.size()));
  return g;
}

// Dataset::softmax of every sequence: [sequence][step][dof].
std::vector<nrl::Outputs> EncodeTargets(const ModelSpec& spec, const Dataset& data) {
  std::vector<nrl::Outputs> y(data.size());
  for (int s = 0; s < data.size(); ++s)
    for (int t = 0; t < data.steps(); ++t) {
      std::vector<VecF> at;
      for (int j = 0; j < data.dofs(); ++j) {
        const float lo = static_cast<float>(spec.output.dofs[j].min), hi = static_cast<float>(spec.output.dofs[j].max);
        at.push_back(nrl::EncodeValue(static_cast<float>(data.sequences[s](j, t)), lo, hi - lo,
                                      nrl::ReferencePoints(spec.output.UnitsFor(j)), static_cast<float>(spec.output.sigma),
                                      false));
      }
      y[s].push_back(at);
    }
  return y;
}

}  // namespace

Model NrlTrainer::InitialModel(const ModelSpec& spec, int steps, int primitives) {
  Model m = nrl::NrlInitialModel(spec, steps, primitives);
  m.provenance = Provenance{};
  m.provenance.source = "NRL's initial state (glibc rand(), NRL's construction order)";
  return m;
}

StatusOr<std::unique_ptr<NrlTrainer>> NrlTrainer::Create(const Model& start, const Dataset& data,
                                                         const NrlTrainerOptions& options) {
  if (Status s = start.spec.Validate(); !s.ok()) return s;
  if (Status s = options.adam.Validate(); !s.ok()) return s;
  const std::string what = "dataset " + data.name + ": ";
  if (data.size() == 0) return Status::InvalidArgument(what + "no sequences");
  if (data.dofs() != start.spec.num_dofs())
    return Status::InvalidArgument(what + std::to_string(data.dofs()) + " DOFs, the model has " +
                                   std::to_string(start.spec.num_dofs()));
  if (data.size() != start.sequences() || data.steps() != start.steps())
    return Status::InvalidArgument(what + std::to_string(data.size()) + " sequences x " + std::to_string(data.steps()) +
                                   " steps, the model's A has " + std::to_string(start.sequences()) + " x " +
                                   std::to_string(start.steps()));
  for (int k = 0; k < data.size(); ++k)
    if (data.SampleOf(k) != 0 || data.PrimitiveOf(k) != k)
      return Status::InvalidArgument(what + "primitive " + std::to_string(data.PrimitiveOf(k)) + " has sample " +
                                     std::to_string(data.SampleOf(k)) +
                                     ": the NRL mode trains one sample per primitive (NRL shares a primitive's "
                                     "forward pass and A among its samples; not reproduced)");
  for (const auto& s : data.sequences)
    if (s.cols() != data.steps()) return Status::InvalidArgument(what + "sequences differ in length");
  return std::unique_ptr<NrlTrainer>(new NrlTrainer(start, data, options));
}

NrlTrainer::NrlTrainer(const Model& start, const Dataset& data, const NrlTrainerOptions& options)
    : base_(start), options_(options), s_(std::make_unique<State>()) {
  State& s = *s_;
  const ModelSpec& spec = start.spec;
  const Weights<float> w = start.weights.Cast<float>();
  const AdaptiveVariables<float> a = start.adaptive.Cast<float>();
  const int K = spec.num_layers();
  s.steps = start.steps();
  s.primitives = start.sequences();
  for (const LayerSpec& l : spec.layers) s.w.push_back(static_cast<float>(l.w));
  s.layers = nrl::MakeLayers(spec, w, s.w);
  for (const nrl::Layer& l : s.layers) {
    s.g.emplace_back(l);
    s.m.emplace_back(l);
    s.v.emplace_back(l);
  }
  nrl::OutputWeights(spec, w, &s.w_out, &s.b_out);
  for (const Eigen::MatrixXf& m : s.w_out) s.w_out_t.push_back(m.transpose());
  s.g_out = s.m_out = s.v_out = ZeroLike(s.w_out, s.b_out);
  s.rec_coef = static_cast<float>(1.0 / static_cast<float>(spec.num_dofs() * 1.0));
  s.reg_coef = static_cast<float>(1.0 / static_cast<float>(w.layout().total_z() * 1.0));
  for (auto* x : {&s.au, &s.al, &s.g_au, &s.g_al, &s.m_au, &s.m_al, &s.v_au, &s.v_al}) x->resize(K);
  for (int k = 0; k < K; ++k) {
    const nrl::Layer& l = s.layers[k];
    for (auto* x : {&s.g_au, &s.g_al, &s.m_au, &s.m_al, &s.v_au, &s.v_al})
      (*x)[k].assign(s.primitives, std::vector<VecF>(s.steps, VecF::Zero(l.z)));
    for (auto* x : {&s.au, &s.al}) (*x)[k].assign(s.primitives, std::vector<VecF>(s.steps));
    for (int p = 0; p < s.primitives; ++p)
      for (int t = 0; t < s.steps; ++t) {
        s.au[k][p][t] = a.mu().col(a.Column(t, p)).segment(l.z_offset, l.z);
        s.al[k][p][t] = a.log_sigma().col(a.Column(t, p)).segment(l.z_offset, l.z);
      }
  }
  s.tr.assign(s.primitives, std::vector<nrl::Trajectory>(K));
  s.x.resize(s.primitives);
  s.y = EncodeTargets(spec, data);
  s.noise.Reset(options.noise, options.seed);
  terms_.kl_per_layer.assign(K, 0.0);
}

NrlTrainer::~NrlTrainer() = default;

// LibNRL::t_background's epoch: every forward, every backward, one Adam step.
const LossTerms& NrlTrainer::Epoch() {
  State& s = *s_;
  const int K = static_cast<int>(s.layers.size());
  const std::vector<nrl::Layer*> layers = s.LayerPointers();
  for (int p = 0; p < s.primitives; ++p) {  // NetworkPvrnn::t_forward from h = d = 0
    nrl::AView au, al;
    for (int k = 0; k < K; ++k) {
      s.tr[p][k].Reset(s.steps, s.layers[k].d, s.layers[k].z);
      au.push_back(&s.au[k][p]);
      al.push_back(&s.al[k][p]);
    }
    std::vector<nrl::Trajectory*> tr = s.TrajectoriesOf(p);
    nrl::ForwardPass(layers, tr, s.steps, au, al, &s.noise, s.w_out, s.b_out, &s.x[p]);
  }
  float rec = 0, reg = 0, loss = 0;
  std::vector<double> kl_total(K, 0.0);
  for (int p = 0; p < s.primitives; ++p) {  // NetworkPvrnn::t_backward
    nrl::BackwardSinks sinks;
    for (int k = 0; k < K; ++k) {
      sinks.g_au.push_back(&s.g_au[k][p]);
      sinks.g_al.push_back(&s.g_al[k][p]);
    }
    sinks.grads = &s.g;
    sinks.out = &s.g_out;
    std::vector<float> kld;
    nrl::BackwardPass(layers, s.TrajectoriesOf(p), s.steps, s.x[p], s.y[p], s.w_out_t, s.rec_coef, &rec, &kld, sinks);
    for (int k = 0; k < K; ++k) {
      reg += s.w[k] * kld[k];
      kl_total[k] += kld[k];
    }
    loss = s.rec_coef * rec + s.reg_coef * reg;
  }
  AdamStep();
  terms_.reconstruction = rec;
  terms_.regulation = reg;
  terms_.loss = loss;
  terms_.kl_per_layer = kl_total;
  return terms_;
}

// NetworkPvrnn::t_optAdam and LayerPvrnn::t_optAdam (each parameter independent: the order does
// not matter), then the transposes NRL keeps.
void NrlTrainer::AdamStep() {
  State& s = *s_;
  const float lr = static_cast<float>(options_.adam.lr), b1 = static_cast<float>(options_.adam.beta1),
              b2 = static_cast<float>(options_.adam.beta2), eps = static_cast<float>(options_.adam.epsilon);
  for (size_t o = 0; o < s.w_out.size(); ++o) {
    nrl::AdamUpdate(&s.w_out[o], &s.g_out.w[o], &s.m_out.w[o], &s.v_out.w[o], step_, lr, b1, b2, eps);
    nrl::AdamUpdate(&s.b_out[o], &s.g_out.b[o], &s.m_out.b[o], &s.v_out.b[o], step_, lr, b1, b2, eps);
    s.w_out_t[o] = s.w_out[o].transpose();
  }
  for (size_t k = 0; k < s.layers.size(); ++k) {
    nrl::Layer& l = s.layers[k];
    nrl::LayerGradients &g = s.g[k], &m = s.m[k], &v = s.v[k];
    for (auto [p, gp, mp, vp] : {std::tuple{&l.Wdh, &g.Wdh, &m.Wdh, &v.Wdh},
                                 {&l.Wzh, &g.Wzh, &m.Wzh, &v.Wzh},
                                 {&l.Wdup, &g.Wdup, &m.Wdup, &v.Wdup},
                                 {&l.Wdlp, &g.Wdlp, &m.Wdlp, &v.Wdlp},
                                 {&l.Wduq, &g.Wduq, &m.Wduq, &v.Wduq},
                                 {&l.Wdlq, &g.Wdlq, &m.Wdlq, &v.Wdlq},
                                 {&l.Wdh_bottom, &g.Wdh_bottom, &m.Wdh_bottom, &v.Wdh_bottom},
                                 {&l.Wdh_top, &g.Wdh_top, &m.Wdh_top, &v.Wdh_top}})
      nrl::AdamUpdate(p, gp, mp, vp, step_, lr, b1, b2, eps);  // (empty for a missing neighbour)
    for (auto [p, gp, mp, vp] : {std::tuple{&l.Bh, &g.Bh, &m.Bh, &v.Bh},
                                 {&l.Bup, &g.Bup, &m.Bup, &v.Bup},
                                 {&l.Blp, &g.Blp, &m.Blp, &v.Blp},
                                 {&l.Buq, &g.Buq, &m.Buq, &v.Buq},
                                 {&l.Blq, &g.Blq, &m.Blq, &v.Blq}})
      nrl::AdamUpdate(p, gp, mp, vp, step_, lr, b1, b2, eps);
    l.RefreshTransposes();
    for (int p = 0; p < s.primitives; ++p)
      for (int t = 0; t < s.steps; ++t) {
        nrl::AdamUpdate(&s.au[k][p][t], &s.g_au[k][p][t], &s.m_au[k][p][t], &s.v_au[k][p][t], step_, lr, b1, b2, eps);
        nrl::AdamUpdate(&s.al[k][p][t], &s.g_al[k][p][t], &s.m_al[k][p][t], &s.v_al[k][p][t], step_, lr, b1, b2, eps);
      }
  }
  ++step_;
}

Model NrlTrainer::Snapshot() const {
  const State& s = *s_;
  Model m = base_;
  m.training.reset();
  Weights<double>& w = m.weights;
  auto put = [&w](const std::string& name, const Eigen::MatrixXf& value) {
    if (const ParameterGroup* g = w.layout().FindGroup(name)) w.Group(*g) = value.cast<double>();
  };
  for (size_t k = 0; k < s.layers.size(); ++k) {
    const nrl::Layer& l = s.layers[k];
    const std::string L = "L" + std::to_string(k) + ".";
    for (auto [name, value] : {std::pair{"W_dh", &l.Wdh},
                               {"W_zh", &l.Wzh},
                               {"W_below", &l.Wdh_bottom},
                               {"W_above", &l.Wdh_top},
                               {"W_mu_p", &l.Wdup},
                               {"W_ls_p", &l.Wdlp},
                               {"W_mu_q", &l.Wduq},
                               {"W_ls_q", &l.Wdlq}})
      put(L + name, *value);
    for (auto [name, value] :
         {std::pair{"b_h", &l.Bh}, {"b_mu_p", &l.Bup}, {"b_ls_p", &l.Blp}, {"b_mu_q", &l.Buq}, {"b_ls_q", &l.Blq}})
      put(L + name, *value);
    for (int p = 0; p < s.primitives; ++p)
      for (int t = 0; t < s.steps; ++t) {
        const int c = m.adaptive.Column(t, p);
        m.adaptive.mu().col(c).segment(l.z_offset, l.z) = s.au[k][p][t].cast<double>();
        m.adaptive.log_sigma().col(c).segment(l.z_offset, l.z) = s.al[k][p][t].cast<double>();
      }
  }
  for (size_t o = 0; o < s.w_out.size(); ++o) {
    put("out.W_x" + std::to_string(o), s.w_out[o]);
    put("out.b_x" + std::to_string(o), s.b_out[o]);
  }
  m.provenance.epochs = epoch();
  return m;
}

}  // namespace dyad::pvrnn
