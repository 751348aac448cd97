// dyad/observer/training.hpp: training data for the intention classifier, generated from the
// PV-RNN prior, and its training (Adam on binary cross-entropy, deterministic per seed).
//
// Training data (the study's recipe): for each primitive p and each noise seed s, the model's
// prior generates `steps` (200) steps with noise on (first 3 steps on p's trained A, as NRL);
// the first `drop` (20) steps are discarded (the transient while the prior settles), the rest is
// one labelled trajectory. Several seeds give variety: each seed draws other prior noise and so
// another variation of the primitive's loop. Every window of `positions_needed` consecutive
// steps of a trajectory is one sample labelled p.
//
// Example:
//   auto model = pvrnn::LoadModel("build/models/demo.dpvrnn");
//   PriorDataOptions data;                              // seeds 1..5, 200 steps, drop 20
//   auto train = GeneratePriorTrajectories(*model, data);
//   TrainOptions options;                               // study's shape, 150 epochs
//   auto classifier = TrainClassifier(ClassifierSpecFor(*model), train, options, nullptr);
#pragma once

#include <functional>
#include <vector>

#include "dyad/observer/classifier.hpp"
#include "dyad/pvrnn/adam.hpp"
#include "dyad/pvrnn/model.hpp"

namespace dyad::observer {

// One trajectory with its known primitive: human traces, prior generations.
struct LabelledTrajectory {
  Eigen::MatrixXd positions;  // dofs x steps, workspace units, oldest first
  int primitive = 0;
};

struct PriorDataOptions {
  std::vector<uint64_t> seeds = {1, 2, 3, 4, 5};  // noise seeds; one trajectory per (seed, primitive)
  int steps = 200;   // generated per trajectory; REQUIRES > drop
  int drop = 20;     // first steps discarded
  bool noise = true; // false: means only (then every seed gives the same trajectory)
};

// Generation seed of trajectory (seed s, primitive p): s * 1000 + p, so every (s, p) pair draws
// its own noise and training and validation seeds never share a trajectory.
uint64_t GenerationSeed(uint64_t seed, int primitive);

// One trajectory per (seed, primitive), seeds outer, primitives inner.
// Fails when steps <= drop or drop < 0 or seeds is empty.
StatusOr<std::vector<LabelledTrajectory>> GeneratePriorTrajectories(const pvrnn::Model& model,
                                                                    const PriorDataOptions& options);

// The study's classifier shape for a model: window 5, hidden 150/100, one output per primitive,
// workspace = the model's output encoding ranges.
ClassifierSpec ClassifierSpecFor(const pvrnn::Model& model, InputRepresentation input = InputRepresentation::kPositions);

// Every window of every trajectory: features (inputs x N) and labels (N).
struct WindowSet {
  Eigen::MatrixXd features;
  std::vector<int> labels;
};
// Fails when a trajectory has another number of DOFs than the spec or a label outside
// [0, spec.classes). Trajectories shorter than spec.positions_needed() contribute nothing.
StatusOr<WindowSet> MakeWindows(const ClassifierSpec& spec, const std::vector<LabelledTrajectory>& trajectories);

struct TrainOptions {
  int epochs = 150;            // passes over the training windows; REQUIRES >= 1
  int batch = 64;              // mini-batch size; REQUIRES >= 1
  uint64_t seed = 1;           // initial weights and the order of samples per epoch
  pvrnn::AdamOptions adam{};   // lr 0.001, betas 0.9/0.999
  int log_every = 0;           // call `progress` every this many epochs (0: never)
};

struct EpochReport {
  int epoch = 0;
  double loss = 0;      // mean training loss over the epoch's batches
  double accuracy = 0;  // argmax accuracy on the training windows at the end of the epoch
};

// Trains a net of shape `spec` on the windows of `trajectories`. Deterministic: same inputs and
// options give the same parameters, bit for bit. `progress` may be null.
StatusOr<Classifier> TrainClassifier(const ClassifierSpec& spec, const std::vector<LabelledTrajectory>& trajectories,
                                     const TrainOptions& options,
                                     const std::function<void(const EpochReport&)>& progress);

}  // namespace dyad::observer
