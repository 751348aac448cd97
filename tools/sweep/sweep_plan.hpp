// tools/sweep/sweep_plan.hpp: a sweep file, read and checked, as the list of runs it asks for.
//
//   sweep: gain                      # its name
//   graph: ../configs/demo.yaml      # the base graph, relative to this file, or instead:
//   study: ../studies/gain.yaml      #   a study's graph...
//   condition: follow                #   ...with this condition's overrides first
//   duration: 30                     # experiment seconds per run (runs are stepped: as fast as they go)
//   recorder: recorder               # the graph's recorder component (default "recorder")
//   set: {mind.model: m.yaml}        # overrides of every run, as `dyad run --set` takes them
//   grid:                            # every combination, first key slowest...
//     mixer.gain: [0.3, 0.6, 0.9]
//     mind.meta_prior: [0.001, 0.01]
//   runs:                            # ...or explicit override sets (one of grid and runs)
//     - {mixer.gain: 0.3, mind.optimizer: ceres}
//   seeds: [1, 2, 3]                 # each combination once per seed (graph key `seed`); default [1]
//                                    # (or `seed: [1, 2, 3]` in grid:, the same; not both)
//   train:                           # optional: the runs use models the sweep trains
//     config: ../train/demo.yaml     # `dyad train`'s config, relative to this file
//     model: mind.model              # the graph's key each trained model goes to (default mind.model)
//     set: {epochs: 5000}            # overrides of every training, as `dyad train --set` takes them
//     grid: {layers.0.w: [0.001, 0.01]}   # one model per combination (default: one model)
//
// Contract of LoadSweep:
//   - Every problem of the file at once, each "file:line:col: key: message" (strict YAML: unknown
//     keys, wrong types, an empty grid or list, both grid and runs, both graph and study, a
//     condition the study lacks, a value repeated in a grid key's list or in seeds, seeds given
//     in grid: and seeds: both, `seed` in a runs: entry; a study file's own problems at its lines).
//   - Every override (each value of each key) is checked against the graph, as `dyad validate
//     --set` would: a key the graph lacks, a value its component refuses. Its problems are
//     reported at the sweep file's line of that value.
//   - Every training value is checked as `dyad train --set` would (the training config's own
//     reader), at the sweep file's line; `model` must name a parameter the graph already sets
//     (a component that takes a model has one).
//   - A training's id is a hash of the config file's text, the content of every file of its
//     data set, its overrides and the dyad version: its model is OUT/models/<id>.dpvrnn, trained
//     once and reused by any sweep into that folder until one of those changes.
//   - Runs come in a fixed order: trainings, then grid (or list) order, then seeds. Each run's
//     id is a hash of the run fully resolved: the graph as run (every file of its extends:
//     chain merged, with all its overrides, the seed among them: Graph::yaml_text), the
//     duration, the content of every file or folder a path parameter (ParamSpec::path) of its
//     components names (a folder: each file's name and bytes; a path to nothing counts as
//     absent), its training's id and the dyad version. Not inputs, so not hashed: the
//     recorder's file and the trained model's key (the sweep sets them per run), and the paths
//     a run writes (recorder.file, counter_sink.file, learner.out, web.port_file,
//     web.token_file). The same run in any sweep, and in a resumed one, has the same id;
//     changing any input gives new ids to exactly the runs that read it.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "dyad/diagnostic.hpp"

namespace dyad::sweep {

struct SweepRun {
  std::string id;                                          // 16 hex digits
  std::vector<std::pair<std::string, std::string>> params;  // the swept keys' values (YAML text), in column order
  int64_t seed = 1;
  std::vector<std::string> sets;  // every `--set KEY=VALUE` of its `dyad run`, but the output file and the model
  int training = -1;              // index in SweepPlan::trainings of the model it runs with; -1: none
};

struct SweepTraining {
  std::string id;                                          // 16 hex digits: names its model file
  std::vector<std::pair<std::string, std::string>> params;  // the swept training keys' values ("train.KEY")
  std::vector<std::string> sets;                            // every `dyad train --set` of it, but the output
};

struct SweepPlan {
  std::string name;
  std::string file;   // the sweep file
  std::string graph;  // the base graph, absolute
  double duration_s = 0;
  std::string recorder = "recorder";
  std::vector<std::string> parameters;  // the swept keys, in column order ("train.KEY" first)
  std::vector<SweepRun> runs;
  std::string train_config;  // absolute; empty: the sweep trains nothing
  std::string model_key = "mind.model";
  std::vector<SweepTraining> trainings;
};

// Where a sweep into `out` keeps the model of `training`.
std::string ModelPath(const std::string& out, const SweepTraining& training);

// Reads and checks `path` (see above); problems are appended to *problems and make the plan
// unusable (check problems->empty()). `plugins`: extra plugin files or folders for the checks.
SweepPlan LoadSweep(const std::string& path, const std::vector<std::string>& plugins, std::vector<Diagnostic>* problems);

}  // namespace dyad::sweep
