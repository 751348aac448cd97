#include "dyad/observer/evaluation.hpp"

#include <cstdio>
#include <random>

namespace dyad::observer {

Eigen::MatrixXd ConfusionMatrix::RowNormalised() const {
  Eigen::MatrixXd m = counts.cast<double>();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    const double s = m.row(i).sum();
    if (s > 0) m.row(i) /= s;
  }
  return m;
}

double ConfusionMatrix::MinDiagonal() const {
  const Eigen::MatrixXd m = RowNormalised();
  double lo = 1.0;
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    if (counts.row(i).sum() > 0) lo = std::min(lo, m(i, i));
  return lo;
}

double ConfusionMatrix::Accuracy() const {
  const int64_t t = total();
  return t == 0 ? 0.0 : static_cast<double>(counts.diagonal().cast<int64_t>().sum()) / static_cast<double>(t);
}

namespace {
std::string Name(const std::vector<std::string>& names, int i) {
  return static_cast<size_t>(i) < names.size() ? names[static_cast<size_t>(i)] : std::to_string(i);
}
}  // namespace

std::string ConfusionMatrix::ToTable(const std::vector<std::string>& names) const {
  const Eigen::MatrixXd m = RowNormalised();
  size_t w = 6;
  for (int i = 0; i < classes(); ++i) w = std::max(w, Name(names, i).size());
  const int width = static_cast<int>(w);
  std::string out;
  char buf[256];
  std::snprintf(buf, sizeof buf, "%-*s", width, "true\\pred");
  out += buf;
  for (int j = 0; j < classes(); ++j) {
    std::snprintf(buf, sizeof buf, " %*s", width, Name(names, j).c_str());
    out += buf;
  }
  out += "  windows\n";
  for (int i = 0; i < classes(); ++i) {
    std::snprintf(buf, sizeof buf, "%-*s", width, Name(names, i).c_str());
    out += buf;
    for (int j = 0; j < classes(); ++j) {
      std::snprintf(buf, sizeof buf, " %*.3f", width, m(i, j));
      out += buf;
    }
    std::snprintf(buf, sizeof buf, "  %d\n", counts.row(i).sum());
    out += buf;
  }
  return out;
}

std::string ConfusionMatrix::ToMarkdown(const std::vector<std::string>& names) const {
  const Eigen::MatrixXd m = RowNormalised();
  std::string out = "| true \\ predicted |";
  for (int j = 0; j < classes(); ++j) out += " " + Name(names, j) + " |";
  out += " windows |\n|---|";
  for (int j = 0; j <= classes(); ++j) out += "---|";
  out += "\n";
  char buf[32];
  for (int i = 0; i < classes(); ++i) {
    out += "| " + Name(names, i) + " |";
    for (int j = 0; j < classes(); ++j) {
      std::snprintf(buf, sizeof buf, i == j ? " **%.3f** |" : " %.3f |", m(i, j));
      out += buf;
    }
    out += " " + std::to_string(counts.row(i).sum()) + " |\n";
  }
  return out;
}

int ArgMax(const Eigen::VectorXd& probabilities) {
  Eigen::Index best = 0;
  if (probabilities.size() > 0) probabilities.maxCoeff(&best);
  return static_cast<int>(best);
}

StatusOr<ConfusionMatrix> EvaluateTrajectories(const Classifier& classifier,
                                               const std::vector<LabelledTrajectory>& trajectories) {
  const ClassifierSpec& spec = classifier.spec();
  auto windows = MakeWindows(spec, trajectories);
  if (!windows.ok()) return windows.status();
  ConfusionMatrix cm;
  cm.counts = Eigen::MatrixXi::Zero(spec.classes, spec.classes);
  if (windows->labels.empty()) return cm;
  const Eigen::MatrixXd p = classifier.Probabilities(windows->features);
  for (Eigen::Index j = 0; j < p.cols(); ++j) cm.counts(windows->labels[static_cast<size_t>(j)], ArgMax(p.col(j))) += 1;
  return cm;
}

std::vector<LabelledTrajectory> DatasetTraces(const pvrnn::Dataset& data, int loops, double noise_std, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<LabelledTrajectory> out;
  for (int p = 0; p < data.size(); ++p) {
    const Eigen::MatrixXd& seq = data.sequences[static_cast<size_t>(p)];
    LabelledTrajectory t;
    t.primitive = p;
    t.positions.resize(seq.rows(), seq.cols() * std::max(loops, 1));
    for (Eigen::Index c = 0; c < t.positions.cols(); ++c)
      for (Eigen::Index i = 0; i < seq.rows(); ++i)
        t.positions(i, c) = seq(i, c % seq.cols()) + (noise_std > 0 ? noise_std * normal(rng) : 0.0);
    out.push_back(std::move(t));
  }
  return out;
}

double InstantCongruence(const Eigen::VectorXd& human, const Eigen::VectorXd& robot) {
  const double sh = human.sum(), sr = robot.sum();
  if (!(sh > 0) || !(sr > 0)) return 0.0;
  return human.dot(robot) / (sh * sr);
}

MovingAverage::MovingAverage(int steps) : ring_(static_cast<size_t>(std::max(steps, 1)), 0.0) {}

void MovingAverage::Reset() {
  next_ = 0;
  count_ = 0;
}

double MovingAverage::Push(double value) {
  ring_[static_cast<size_t>(next_)] = value;
  next_ = (next_ + 1) % static_cast<int>(ring_.size());
  count_ = std::min(count_ + 1, static_cast<int>(ring_.size()));
  // Summed afresh (Y is small): no drift from a running sum.
  double sum = 0;
  for (int i = 0; i < count_; ++i) sum += ring_[static_cast<size_t>(i)];
  return sum / count_;
}

}  // namespace dyad::observer
