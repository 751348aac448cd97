// dyad/pvrnn/model_spec.hpp: the shape and settings of a PV-RNN model, independent of weights.
//
// Contract
// - Layers are listed from the lowest (fastest, index 0, feeds the output) to the highest.
// - Each layer k has d_k deterministic units, z_k stochastic units, time constant tau_k >= 1 and
//   a training meta-prior w_k >= 0. Adjacent layers are connected both ways (NRL topology).
// - The output is a softmax code per degree of freedom (DOF); `OutputEncoding` maps positions to
//   codes and back (see softmax_encoding.hpp). `units_per_dof()` = ceil((max-min)/dsoft).
// - `Problems()` lists every broken constraint, each naming the field (the model file's keys,
//   e.g. "layers[1].d", "output.dsoft") and saying what is wrong with the value;
//   `Validate()` returns the first as InvalidArgument ("layers[1].d: must be in 1..100000, got 0").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dyad/status.hpp"

namespace dyad::pvrnn {

// One broken constraint of a settings struct: `field` as spelled in files ("layers[1].d",
// "adam.lr") and `message` ("must be > 0, got -1").
struct FieldProblem {
  std::string field;
  std::string message;
  std::string ToString() const { return field + ": " + message; }
};

struct LayerSpec {
  int d = 10;         // deterministic units; REQUIRES 1..100000
  int z = 1;          // stochastic units; REQUIRES 1..100000
  double tau = 2.0;   // time constant (steps); REQUIRES finite, >= 1
  double w = 0.01;    // meta-prior (weight of KL) used in training; REQUIRES finite, >= 0
};

struct DofRange {
  double min = -50.0;  // workspace units; REQUIRES finite
  double max = 50.0;   // REQUIRES finite, > min
};

struct OutputEncoding {
  std::vector<DofRange> dofs;  // one per output dimension; REQUIRES non-empty
  double dsoft = 10.0;         // workspace units per softmax unit; REQUIRES finite, > 0,
                               // at most 10000 units per DOF
  double sigma = 0.2;          // width of the code on [0,1]; REQUIRES finite, > 0
  // Softmax units of one DOF, n = ceil((max - min) / dsoft) (at least 2).
  int UnitsFor(int dof) const;
  int TotalUnits() const;
};

struct ModelSpec {
  static constexpr int64_t kMaxWeights = 100'000'000;  // 800 MB in double
  std::vector<LayerSpec> layers;  // bottom (fast) first; REQUIRES non-empty and at most
                                  // kMaxWeights weights and biases in all
  OutputEncoding output;

  int num_layers() const { return static_cast<int>(layers.size()); }
  int total_d() const;
  int total_z() const;
  int num_dofs() const { return static_cast<int>(output.dofs.size()); }
  std::vector<FieldProblem> Problems() const;
  Status Validate() const;

  // The study's MacawBot shape: d=40,10; z=4,1; tau=2,10; w=0.01,0.01; 2 DOF on -50..50,
  // dsoft=10, sigma=0.2.
  static ModelSpec MacawBot();
  bool operator==(const ModelSpec& other) const;
};

}  // namespace dyad::pvrnn
