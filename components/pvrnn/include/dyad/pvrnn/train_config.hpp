// dyad/pvrnn/train_config.hpp: the YAML file of `dyad train`.
//
//   dataset: ../../../shared/data/vcbot/dataset/Macaw   # relative to this file's folder
//   loops: 1                                   # train on each primitive repeated N times
//   layers:                                    # bottom (fast) first
//     - {d: 40, z: 4, tau: 2, w: 0.01}
//     - {d: 10, z: 1, tau: 10, w: 0.01}
//   encoding: {dofs: [[-50, 50], [-50, 50]], dsoft: 10, sigma: 0.2}   # softmax output code
//   epochs: 50000
//   adam: {lr: 0.001, beta1: 0.9, beta2: 0.999, epsilon: 1.0e-8}
//   seed: 1
//   scalar: float                              # float | double
//   threads: 0                                 # 0: the hardware's cores (same result for any)
//   noise: true                                # sample eps during training
//   prior: dyad                                # dyad | nrl: NRL's training (below)
//   log_every: 100                             # progress line + CSV row
//   checkpoint_every: 5000                     # 0 = only at the end / on Ctrl-C
//   output: macaw.dpvrnn                       # relative to this file's folder
//   checkpoint: macaw.ckpt.dpvrnn              # default: <output>.ckpt
//   log_csv: macaw.csv                         # default: <output>.csv
//
// Contract: unknown keys, wrong types and invalid values are errors, each reported as
// "file:line:col: key: message" (1-based), all of them at once. `overrides` ("adam.lr=0.002")
// replace values before validation and are reported as "--set KEY=VALUE: key: message"
// (dyad/strict_yaml.hpp, the reader the graph file uses too).
// `prior: nrl` trains NRL's way (NrlTrainer, dyad/pvrnn/nrl_trainer.hpp): NRL's initial state,
// its free-running prior in the KL with its gradient, its Adam, float; adam.epsilon defaults to
// NRL's 1e-20 there (written in the file, it is kept), scalar must be float, `seed` seeds NRL's
// noise engine (NRL: 0), `threads` and `checkpoint_every` are not used.
// Paths (dataset, output, checkpoint, log_csv) come back absolute: written in the file, relative
// to the file's folder; given as an override, relative to the working folder.
#pragma once

#include <string>
#include <vector>

#include "dyad/pvrnn/adam.hpp"
#include "dyad/pvrnn/model_spec.hpp"
#include "dyad/status.hpp"

namespace dyad::pvrnn {

struct TrainConfig {
  std::string dataset;             // absolute (see the file comment)
  // Each sequence is trained as `loops` copies of itself end to end (1..100). For closed
  // primitives: with 2 the prior learns to go round again instead of drifting after one loop.
  int64_t loops = 1;
  ModelSpec spec;
  int64_t epochs = 50000;          // REQUIRES > 0
  AdamOptions adam;
  uint64_t seed = 1;
  std::string scalar = "float";    // "float" | "double"
  bool noise = true;
  std::string prior = "dyad";  // "dyad" | "nrl"
  // Threads of the trainer (TrainerOptions::threads): the result is the same for any; 1 is
  // faster when other processes keep every core busy.
  int64_t threads = 0;             // REQUIRES 0..256 (0: the hardware's cores)
  int64_t log_every = 100;         // REQUIRES > 0
  int64_t checkpoint_every = 5000; // REQUIRES >= 0
  std::string output;              // REQUIRED
  std::string checkpoint;          // default output + ".ckpt"
  std::string log_csv;             // default output + ".csv"
};

StatusOr<TrainConfig> LoadTrainConfig(const std::string& path,
                                      const std::vector<std::string>& overrides = {});

}  // namespace dyad::pvrnn
