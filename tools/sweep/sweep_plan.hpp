// tools/sweep/sweep_plan.hpp: a sweep file, read and checked, as the list of runs it asks for.
//
//   sweep: gain                      # its name
//   graph: ../configs/demo.yaml      # the base graph, relative to this file
//   duration: 30                     # experiment seconds per run (runs are stepped: as fast as they go)
//   recorder: recorder               # the graph's recorder component (default "recorder")
//   set: {mind.model: m.yaml}        # overrides of every run, as `dyad run --set` takes them
//   grid:                            # every combination, first key slowest...
//     mixer.gain: [0.3, 0.6, 0.9]
//     mind.meta_prior: [0.001, 0.01]
//   runs:                            # ...or explicit override sets (one of grid and runs)
//     - {mixer.gain: 0.3, mind.optimizer: ceres}
//   seeds: [1, 2, 3]                 # each combination once per seed (graph key `seed`); default [1]
//
// Contract of LoadSweep:
//   - Every problem of the file at once, each "file:line:col: key: message" (strict YAML: unknown
//     keys, wrong types, an empty grid or list, both grid and runs).
//   - Every override (each value of each key) is checked against the graph, as `dyad validate
//     --set` would: a key the graph lacks, a value its component refuses. Its problems are
//     reported at the sweep file's line of that value.
//   - Runs come in a fixed order: grid (or list) order, then seeds. Each run's id is a hash of
//     the graph file's text, its overrides and the dyad version: the same run in any sweep, and
//     in a resumed one, has the same id.
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
  std::vector<std::string> sets;  // every `--set KEY=VALUE` of its `dyad run`, but the output file
};

struct SweepPlan {
  std::string name;
  std::string file;   // the sweep file
  std::string graph;  // the base graph, absolute
  double duration_s = 0;
  std::string recorder = "recorder";
  std::vector<std::string> parameters;  // the swept keys, in column order
  std::vector<SweepRun> runs;
};

// Reads and checks `path` (see above); problems are appended to *problems and make the plan
// unusable (check problems->empty()). `plugins`: extra plugin files or folders for the checks.
SweepPlan LoadSweep(const std::string& path, const std::vector<std::string>& plugins, std::vector<Diagnostic>* problems);

}  // namespace dyad::sweep
