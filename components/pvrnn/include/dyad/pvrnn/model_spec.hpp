// dyad/pvrnn/model_spec.hpp: the shape and settings of a PV-RNN model, independent of weights.
//
// Contract
// - Layers are listed from the lowest (fastest, index 0, feeds the output) to the highest.
// - Each layer k has d_k deterministic units, z_k stochastic units, time constant tau_k >= 1 and
//   a training meta-prior w_k >= 0. Adjacent layers are connected both ways (NRL topology).
// - The output is a softmax code per degree of freedom (DOF); `OutputEncoding` maps positions to
//   codes and back (see softmax_encoding.hpp). `units_per_dof()` = ceil((max-min)/dsoft).
// - `Validate()` returns InvalidArgument naming the field, its value and the broken constraint.
#pragma once

#include <string>
#include <vector>

#include "dyad/status.hpp"

namespace dyad::pvrnn {

struct LayerSpec {
  int d = 10;         // deterministic units; REQUIRES > 0
  int z = 1;          // stochastic units; REQUIRES > 0
  double tau = 2.0;   // time constant (steps); REQUIRES >= 1
  double w = 0.01;    // meta-prior (weight of KL) used in training; REQUIRES >= 0
};

struct DofRange {
  double min = -50.0;  // workspace units
  double max = 50.0;   // REQUIRES > min
};

struct OutputEncoding {
  std::vector<DofRange> dofs;  // one per output dimension; REQUIRES non-empty
  double dsoft = 10.0;         // workspace units per softmax unit; REQUIRES > 0
  double sigma = 0.2;          // width of the code on [0,1]; REQUIRES > 0
  // Softmax units of one DOF, n = ceil((max - min) / dsoft) (at least 2).
  int UnitsFor(int dof) const;
  int TotalUnits() const;
};

struct ModelSpec {
  std::vector<LayerSpec> layers;  // bottom (fast) first; REQUIRES non-empty
  OutputEncoding output;

  int num_layers() const { return static_cast<int>(layers.size()); }
  int total_d() const;
  int total_z() const;
  int num_dofs() const { return static_cast<int>(output.dofs.size()); }
  Status Validate() const;

  // The study's MacawBot shape: d=40,10; z=4,1; tau=2,10; w=0.01,0.01; 2 DOF on -50..50,
  // dsoft=10, sigma=0.2.
  static ModelSpec MacawBot();
  bool operator==(const ModelSpec& other) const;
};

}  // namespace dyad::pvrnn
