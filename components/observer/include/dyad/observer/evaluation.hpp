// dyad/observer/evaluation.hpp: how well the classifier recognises labelled motion, and the
// intention congruence of two classifications.
//
// Confusion matrix: every window of every labelled trajectory is classified (argmax of the
// sigmoid outputs) and counted in row = true primitive, column = predicted primitive. Rows are
// normalised for reading: the diagonal is the per-primitive recall. `dyad train-observer` prints
// it for prior-generated validation data; `dyad analyze` uses it for human traces with a known
// target primitive (e.g. the synthetic human's intervention events).
//
// Example (dyad analyze):
//   std::vector<LabelledTrajectory> traces = ...;   // human positions during each event + target
//   auto cm = EvaluateTrajectories(observer.classifier, traces);
//   std::printf("%s", cm->ToTable({"eye", "head", ...}).c_str());
//
// Congruence P(C_t) (docs/components.md#observer): with h and r the sigmoid outputs of the
// human's and the robot's windows, normalised to sum 1 (h^ = h / sum h), the instantaneous
// congruence is the probability that a primitive drawn from h^ and one drawn from r^ coincide:
//   c_t = sum_k h^_k r^_k  in [0, 1]   (1: both certain of the same primitive).
// P(C_t) is c_t low-pass filtered by a moving average over the last Y values (fewer while fewer
// exist since the last Reset); study: Y = 10.
#pragma once

#include <string>
#include <vector>

#include "dyad/observer/training.hpp"
#include "dyad/pvrnn/dataset.hpp"

namespace dyad::observer {

struct ConfusionMatrix {
  Eigen::MatrixXi counts;  // classes x classes; rows: true primitive, columns: predicted

  int classes() const { return static_cast<int>(counts.rows()); }
  int64_t total() const { return counts.cast<int64_t>().sum(); }
  // Each row divided by its sum (rows without samples stay 0).
  Eigen::MatrixXd RowNormalised() const;
  // Smallest diagonal entry of RowNormalised() over rows that have samples (1 when none has).
  double MinDiagonal() const;
  // Correct windows / all windows.
  double Accuracy() const;
  // A plain-text table: one row per true primitive with the row-normalised values (3 decimals)
  // and the row's sample count. `names` labels rows/columns (indices when empty or too short).
  std::string ToTable(const std::vector<std::string>& names = {}) const;
  // The same as Markdown (for reports).
  std::string ToMarkdown(const std::vector<std::string>& names = {}) const;
};

// Index of the largest output (the first on ties).
int ArgMax(const Eigen::VectorXd& probabilities);

// Classifies every window of every trajectory. Fails like MakeWindows (wrong DOFs, bad label).
StatusOr<ConfusionMatrix> EvaluateTrajectories(const Classifier& classifier,
                                               const std::vector<LabelledTrajectory>& trajectories);

// Traces of a data set's primitives as a synthetic human draws them (human_synthetic): each
// primitive looped `loops` times, plus N(0, noise_std^2) per axis from one std::mt19937_64
// seeded with `seed`; labelled with the primitive's index. All DOFs of the data set are kept
// (they must match the classifier's).
std::vector<LabelledTrajectory> DatasetTraces(const pvrnn::Dataset& data, int loops, double noise_std, uint64_t seed);

// c_t = sum_k h^_k r^_k (above). Returns 0 when either side sums to 0 (no evidence).
// REQUIRES human.size() == robot.size().
double InstantCongruence(const Eigen::VectorXd& human, const Eigen::VectorXd& robot);

// Moving average over the last `steps` values pushed since the last Reset. No allocation
// after construction.
class MovingAverage {
 public:
  explicit MovingAverage(int steps);  // REQUIRES steps >= 1
  void Reset();
  // Adds a value and returns the mean of the last min(steps, pushed) values.
  double Push(double value);
  int count() const { return count_; }

 private:
  std::vector<double> ring_;
  int next_ = 0, count_ = 0;
};

}  // namespace dyad::observer
