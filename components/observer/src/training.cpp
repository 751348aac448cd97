#include "dyad/observer/training.hpp"

#include <algorithm>
#include <numeric>
#include <random>

#include "dyad/observer/evaluation.hpp"
#include "dyad/pvrnn/prior_generator.hpp"

namespace dyad::observer {

uint64_t GenerationSeed(uint64_t seed, int primitive) { return seed * 1000 + static_cast<uint64_t>(primitive); }

StatusOr<std::vector<LabelledTrajectory>> GeneratePriorTrajectories(const pvrnn::Model& model,
                                                                    const PriorDataOptions& options) {
  if (options.seeds.empty()) return Status::InvalidArgument("prior data: seeds: must list at least one seed");
  if (options.drop < 0 || options.steps <= options.drop)
    return Status::InvalidArgument("prior data: steps " + std::to_string(options.steps) + ", drop " +
                                   std::to_string(options.drop) + ": need 0 <= drop < steps");
  std::vector<LabelledTrajectory> out;
  for (uint64_t s : options.seeds) {
    for (int p = 0; p < model.sequences(); ++p) {
      pvrnn::GenerateOptions g;
      g.noise = options.noise;
      g.seed = GenerationSeed(s, p);
      const Eigen::MatrixXd xy = pvrnn::GeneratePrimitive(model, p, options.steps, g);
      LabelledTrajectory t;
      t.positions = xy.rightCols(options.steps - options.drop);
      t.primitive = p;
      out.push_back(std::move(t));
    }
  }
  return out;
}

ClassifierSpec ClassifierSpecFor(const pvrnn::Model& model, InputRepresentation input) {
  ClassifierSpec spec;
  spec.classes = model.sequences();
  spec.input = input;
  spec.workspace = model.spec.output.dofs;
  return spec;
}

StatusOr<WindowSet> MakeWindows(const ClassifierSpec& spec, const std::vector<LabelledTrajectory>& trajectories) {
  const int need = spec.positions_needed();
  int64_t n = 0;
  for (size_t i = 0; i < trajectories.size(); ++i) {
    const auto& t = trajectories[i];
    if (t.positions.rows() != spec.dofs())
      return Status::InvalidArgument("trajectory " + std::to_string(i) + ": has " + std::to_string(t.positions.rows()) +
                                     " DOFs, the classifier " + std::to_string(spec.dofs()));
    if (t.primitive < 0 || t.primitive >= spec.classes)
      return Status::InvalidArgument("trajectory " + std::to_string(i) + ": primitive " + std::to_string(t.primitive) +
                                     " outside 0.." + std::to_string(spec.classes - 1));
    n += std::max<int64_t>(0, t.positions.cols() - need + 1);
  }
  WindowSet w;
  w.features.resize(spec.inputs(), n);
  w.labels.reserve(static_cast<size_t>(n));
  int64_t col = 0;
  for (const auto& t : trajectories) {
    for (int64_t s = 0; s + need <= t.positions.cols(); ++s) {
      ComputeFeatures(spec, t.positions.middleCols(s, need), w.features.col(col++));
      w.labels.push_back(t.primitive);
    }
  }
  return w;
}

StatusOr<Classifier> TrainClassifier(const ClassifierSpec& spec, const std::vector<LabelledTrajectory>& trajectories,
                                     const TrainOptions& options,
                                     const std::function<void(const EpochReport&)>& progress) {
  if (options.epochs < 1) return Status::InvalidArgument("epochs: must be >= 1, got " + std::to_string(options.epochs));
  if (options.batch < 1) return Status::InvalidArgument("batch: must be >= 1, got " + std::to_string(options.batch));
  if (Status s = options.adam.Validate(); !s.ok()) return s;
  auto made = Classifier::Create(spec, options.seed);
  if (!made.ok()) return made.status();
  Classifier c = std::move(made.value());
  auto windows = MakeWindows(spec, trajectories);
  if (!windows.ok()) return windows.status();
  const WindowSet& w = windows.value();
  const int64_t n = w.features.cols();
  if (n == 0) return Status::InvalidArgument("training data: no trajectory is long enough for one window");

  Eigen::MatrixXd targets = Eigen::MatrixXd::Zero(spec.classes, n);
  for (int64_t j = 0; j < n; ++j) targets(w.labels[static_cast<size_t>(j)], j) = 1.0;

  pvrnn::Adam<double> adam(static_cast<int>(c.parameters().size()), options.adam);
  std::mt19937_64 rng(options.seed ^ 0x9e3779b97f4a7c15ull);  // sample order; independent of the init stream
  std::vector<int64_t> order(static_cast<size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  Eigen::MatrixXd xb, yb;
  Eigen::VectorXd grad;
  for (int e = 1; e <= options.epochs; ++e) {
    // Fisher-Yates with our own draws: std::shuffle's algorithm is implementation-defined.
    for (size_t i = order.size() - 1; i > 0; --i) {
      const size_t j = static_cast<size_t>(rng() % (i + 1));
      std::swap(order[i], order[j]);
    }
    double loss_sum = 0;
    int batches = 0;
    for (int64_t at = 0; at < n; at += options.batch) {
      const int64_t m = std::min<int64_t>(options.batch, n - at);
      xb.resize(spec.inputs(), m);
      yb.resize(spec.classes, m);
      for (int64_t j = 0; j < m; ++j) {
        xb.col(j) = w.features.col(order[static_cast<size_t>(at + j)]);
        yb.col(j) = targets.col(order[static_cast<size_t>(at + j)]);
      }
      loss_sum += c.Loss(xb, yb, &grad);
      ++batches;
      adam.Step(c.parameters(), grad);
    }
    if (progress && options.log_every > 0 && (e % options.log_every == 0 || e == options.epochs)) {
      EpochReport r;
      r.epoch = e;
      r.loss = loss_sum / batches;
      const Eigen::MatrixXd p = c.Probabilities(w.features);
      int64_t correct = 0;
      for (int64_t j = 0; j < n; ++j) correct += ArgMax(p.col(j)) == w.labels[static_cast<size_t>(j)];
      r.accuracy = static_cast<double>(correct) / static_cast<double>(n);
      progress(r);
    }
  }
  return c;
}

}  // namespace dyad::observer
