// dyad/observer/classifier.hpp: the study's intention classifier. A feed-forward net that maps
// the last few steps of a 2-DOF motion to one sigmoid output per drawing primitive.
//
//   input  = features of a `window`-step window (ClassifierSpec::input, below), window*dofs values
//   h1     = tanh(W0 input + b0)        hidden[0] units (study: 150)
//   h2     = tanh(W1 h1 + b1)           hidden[1] units (study: 100)
//   p      = sigmoid(W2 h2 + b2)        `classes` outputs, one per primitive (study: 7)
//
// Loss (training): binary cross-entropy of every output against the one-hot target, summed over
// outputs and averaged over samples (computed from the logits, numerically stable).
//
// Input representations (picked by measurement, see docs/components.md#observer):
//   kPositions     the window's positions, each DOF mapped from its workspace range [min, max]
//                  to [-1, 1]. Needs `window` positions.
//   kDisplacements the window's per-step displacements p_t - p_{t-1}, divided by 5% of the DOF's
//                  range (5 units on -50..50). Needs `window + 1` positions.
// Features are ordered by time, oldest first: [x_0, y_0, x_1, y_1, ...].
//
// Contract
// - All parameters live in one flat vector (`parameters()`), layer by layer, each layer W
//   (column-major, out x in) then b; Adam steps that vector.
// - `Create` is deterministic for a given seed (Xavier-uniform weights, zero biases).
// - Classify() allocates nothing once its Workspace has been used with the same spec.
//
// Example:
//   ClassifierSpec spec;                       // study's shape, 7 primitives, -50..50
//   auto c = Classifier::Create(spec, 1);      // untrained
//   Eigen::MatrixXd window(2, spec.positions_needed());   // dofs x positions, oldest first
//   Classifier::Workspace ws;
//   Eigen::VectorXd p(spec.classes);
//   c->Classify(window, &ws, &p);              // p(k) = sigmoid output of primitive k
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "dyad/pvrnn/model_spec.hpp"
#include "dyad/status.hpp"

namespace dyad::observer {

using pvrnn::DofRange;
using pvrnn::FieldProblem;

enum class InputRepresentation { kPositions, kDisplacements };

// "positions" / "displacements".
const char* ToString(InputRepresentation r);
// Parses the names above; false for anything else.
bool ParseInputRepresentation(const std::string& text, InputRepresentation* out);

struct ClassifierSpec {
  int window = 5;                   // steps per input; REQUIRES 1..1000
  std::vector<int> hidden = {150, 100};  // tanh layers; REQUIRES each 1..100000, at least one
  int classes = 7;                  // sigmoid outputs (primitives); REQUIRES 1..1000
  InputRepresentation input = InputRepresentation::kPositions;
  // One per DOF: the workspace range used to normalise features; REQUIRES non-empty, min < max.
  std::vector<DofRange> workspace = {{-50, 50}, {-50, 50}};

  int dofs() const { return static_cast<int>(workspace.size()); }
  int inputs() const { return window * dofs(); }
  // Positions a window of features is computed from (window, or window + 1 for displacements).
  int positions_needed() const { return input == InputRepresentation::kDisplacements ? window + 1 : window; }
  // Number of parameters of the net.
  int64_t num_parameters() const;

  // Every broken constraint ("hidden[1]": "must be in 1..100000, got 0"); Validate: the first.
  std::vector<FieldProblem> Problems() const;
  Status Validate() const;
  bool operator==(const ClassifierSpec& o) const;
};

// Writes the features of one window into `out` (spec.inputs()).
// REQUIRES positions.rows() == spec.dofs(), positions.cols() == spec.positions_needed().
void ComputeFeatures(const ClassifierSpec& spec, const Eigen::Ref<const Eigen::MatrixXd>& positions,
                     Eigen::Ref<Eigen::VectorXd> out);

class Classifier {
 public:
  // Buffers for Classify(); reused between calls (no allocation after the first).
  struct Workspace {
    Eigen::VectorXd features;
    std::vector<Eigen::VectorXd> activations;
  };

  Classifier() = default;
  // Untrained net: Xavier-uniform weights from `seed`, zero biases. Fails when spec is invalid.
  static StatusOr<Classifier> Create(const ClassifierSpec& spec, uint64_t seed);
  // A net with given parameters (e.g. read from a file). REQUIRES
  // parameters.size() == spec.num_parameters(); fails otherwise or when spec is invalid.
  static StatusOr<Classifier> FromParameters(const ClassifierSpec& spec, Eigen::VectorXd parameters);

  const ClassifierSpec& spec() const { return spec_; }
  const Eigen::VectorXd& parameters() const { return params_; }
  Eigen::VectorXd& parameters() { return params_; }

  // Sigmoid outputs for a batch of feature columns (inputs x N) -> classes x N.
  Eigen::MatrixXd Probabilities(const Eigen::MatrixXd& features) const;

  // Mean binary cross-entropy of the batch (features: inputs x N, targets: classes x N with
  // values in [0, 1]); when `gradient` is non-null it receives dLoss/dparameters.
  double Loss(const Eigen::MatrixXd& features, const Eigen::MatrixXd& targets, Eigen::VectorXd* gradient) const;

  // Sigmoid outputs for one window of positions (dofs x positions_needed, oldest first).
  // `probabilities` is resized to classes (no allocation when already that size).
  void Classify(const Eigen::Ref<const Eigen::MatrixXd>& positions, Workspace* ws,
                Eigen::VectorXd* probabilities) const;

 private:
  // Offsets of layer l's W and b in params_; in/out sizes.
  struct LayerView {
    int64_t w = 0, b = 0;
    int in = 0, out = 0;
  };
  explicit Classifier(const ClassifierSpec& spec);
  Eigen::Map<const Eigen::MatrixXd> W(int l) const;
  Eigen::Map<const Eigen::VectorXd> B(int l) const;

  ClassifierSpec spec_;
  std::vector<LayerView> layers_;
  Eigen::VectorXd params_;
};

}  // namespace dyad::observer
