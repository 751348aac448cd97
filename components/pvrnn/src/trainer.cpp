#include "dyad/pvrnn/trainer.hpp"

#include <algorithm>
#include <numeric>
#include <sstream>
#include <thread>

#include "dyad/pvrnn/prior_generator.hpp"
#include "dyad/pvrnn/softmax_encoding.hpp"
#include "task_pool.hpp"

namespace dyad::pvrnn {

template <typename Scalar>
StatusOr<std::unique_ptr<Trainer<Scalar>>> Trainer<Scalar>::Create(const Model& model,
                                                                   const Dataset& data,
                                                                   const TrainerOptions& options) {
  if (Status s = model.spec.Validate(); !s.ok()) return s;
  if (Status s = options.adam.Validate(); !s.ok()) return s;
  if (options.chunks < 1)
    return Status::InvalidArgument("chunks: must be >= 1, got " + std::to_string(options.chunks));
  if (options.threads < 0)
    return Status::InvalidArgument("threads: must be >= 0, got " + std::to_string(options.threads));
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
          m << "dataset " << data.name << ": primitive " << data.PrimitiveOf(p);
          if (data.SequencesPerPrimitive()[data.PrimitiveOf(p)] > 1) m << ", sample " << data.SampleOf(p);
          m << ", step " << t << " (row " << t + 1 << "), DOF " << i
            << " = " << v << ": outside the encoding range [" << r.min << ", " << r.max
            << "] by more than half its width";
          return Status::InvalidArgument(m.str());
        }
      }
  return std::unique_ptr<Trainer>(new Trainer(model, data, options));
}

template <typename Scalar>
Trainer<Scalar>::Chunk::Chunk(const NetworkLayout& layout, int first_seq, int n, int steps)
    : first(first_seq),
      count(n),
      pass(layout, steps, n),
      a(layout.total_z(), steps, n),
      grad_a(layout.total_z(), steps, n),
      grad_w(layout),
      eps(MatrixT<Scalar>::Zero(layout.total_z(), steps * n)),
      start(NetworkState<Scalar>::Zero(layout.total_d(), n)) {}

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
      rng_(options.seed) {
  w_.ApplyMask();
  const int S = data.size(), T = data.steps();
  Eigen::MatrixXd positions(data.dofs(), T * S);
  for (int t = 0; t < T; ++t)
    for (int s = 0; s < S; ++s) positions.col(t * S + s) = data.sequences[s].col(t);
  targets_ = EncodePositions(model.spec.output, positions).cast<Scalar>();
  eps_ = MatrixT<Scalar>::Zero(layout_.total_z(), T * S);
  eps_next_ = eps_;
  MakeChunks(S, T, targets_);
  terms_.kl_per_layer.assign(layout_.num_layers(), 0.0);
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
Trainer<Scalar>::~Trainer() = default;

// Consecutive sequences per chunk (sizes differ by at most one), each chunk's targets copied
// once; the thread pool sized to the chunks.
template <typename Scalar>
void Trainer<Scalar>::MakeChunks(int S, int T, const MatrixT<Scalar>& targets) {
  const int n_chunks = std::min(options_.chunks, S);
  for (int c = 0; c < n_chunks; ++c) {
    const int first = c * S / n_chunks, count = (c + 1) * S / n_chunks - first;
    auto chunk = std::make_unique<Chunk>(layout_, first, count, T);
    chunk->targets.resize(targets.rows(), T * count);
    for (int t = 0; t < T; ++t)
      chunk->targets.middleCols(t * count, count) = targets.middleCols(t * S + first, count);
    chunks_.push_back(std::move(chunk));
    by_size_.push_back(c);
  }
  std::stable_sort(by_size_.begin(), by_size_.end(),
                   [this](int x, int y) { return chunks_[x]->count > chunks_[y]->count; });
  int threads = options_.threads;
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  pool_ = std::make_unique<internal::TaskPool>(std::min(threads, n_chunks));
}

template <typename Scalar>
int Trainer<Scalar>::threads() const {
  return pool_->threads();
}

// Runs on any thread: reads the shared A, eps and weights, writes only the chunk and its
// columns of grad_a_.
template <typename Scalar>
void Trainer<Scalar>::RunChunk(Chunk& c) {
  const int S = a_.sequences(), n = c.count;
  for (int t = 0; t < a_.steps(); ++t) {
    c.a.mu().middleCols(t * n, n) = a_.mu().middleCols(t * S + c.first, n);
    c.a.log_sigma().middleCols(t * n, n) = a_.log_sigma().middleCols(t * S + c.first, n);
    c.eps.middleCols(t * n, n) = eps_.middleCols(t * S + c.first, n);
  }
  c.terms = &c.pass.Forward(w_, c.a, c.eps, c.targets, c.start, meta_prior_);
  c.pass.Backward(&c.grad_w, &c.grad_a);
  for (int t = 0; t < a_.steps(); ++t) {
    grad_a_.mu().middleCols(t * S + c.first, n) = c.grad_a.mu().middleCols(t * n, n);
    grad_a_.log_sigma().middleCols(t * S + c.first, n) = c.grad_a.log_sigma().middleCols(t * n, n);
  }
}

// Tasks, claimed in this order: the chunks' passes (largest first), then the next epoch's eps,
// which the thread of a smaller chunk draws while the largest still runs. (Measured: splitting
// each chunk's weight products into tasks of their own is slower, their data are in the cache
// of the thread that ran the pass.)
template <typename Scalar>
void Trainer<Scalar>::RunTask(int task) {
  if (task < chunks())
    RunChunk(*chunks_[by_size_[task]]);
  else
    SampleNoise(eps_next_);
}

// In chunk order, whichever thread ran which chunk: the sums do not depend on the threads.
template <typename Scalar>
void Trainer<Scalar>::SumChunks() {
  grad_w_.flat() = chunks_[0]->grad_w.flat();
  terms_.reconstruction = terms_.regulation = 0;
  std::fill(terms_.kl_per_layer.begin(), terms_.kl_per_layer.end(), 0.0);
  for (size_t c = 0; c < chunks_.size(); ++c) {
    if (c > 0) grad_w_.flat() += chunks_[c]->grad_w.flat();
    const LossTerms& t = *chunks_[c]->terms;
    terms_.reconstruction += t.reconstruction;
    terms_.regulation += t.regulation;
    for (size_t k = 0; k < t.kl_per_layer.size(); ++k) terms_.kl_per_layer[k] += t.kl_per_layer[k];
  }
  terms_.loss = terms_.reconstruction / layout_.spec().num_dofs() + terms_.regulation / layout_.total_z();
}

template <typename Scalar>
void Trainer<Scalar>::SampleNoise(MatrixT<Scalar>& eps) {
  Scalar* e = eps.data();
  for (int i = 0; i < eps.size(); ++i) e[i] = static_cast<Scalar>(normal_(rng_));
}

// The next epoch's eps are drawn (same generator, same order) as one more task beside the
// chunks (see RunTask); a checkpoint records the generator as it was before.
template <typename Scalar>
const LossTerms& Trainer<Scalar>::Epoch() {
  const bool noise = options_.sample_noise;
  if (noise) {
    if (eps_next_ready_)
      eps_.swap(eps_next_);
    else
      SampleNoise(eps_);
    rng_before_next_ = rng_;
    normal_before_next_ = normal_;
  }
  auto run = [this](int task) { RunTask(task); };
  pool_->Run(chunks() + (noise ? 1 : 0), run);
  eps_next_ready_ = noise;
  SumChunks();
  adam_w_.Step(w_.flat(), grad_w_.flat());
  adam_a_.Step(a_.flat(), grad_a_.flat());
  return terms_;
}

template <typename Scalar>
double Trainer<Scalar>::MultiplyAddsPerEpoch() const {
  double sum = 0;
  for (const auto& c : chunks_) sum += c->pass.MultiplyAddsPerIteration();
  return sum;
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
    if (eps_next_ready_)
      out << rng_before_next_ << ' ' << normal_before_next_;
    else
      out << rng_ << ' ' << normal_;
    st.rng_state = out.str();
    m.training = std::move(st);
  }
  return m;
}

template class Trainer<float>;
template class Trainer<double>;

}  // namespace dyad::pvrnn
