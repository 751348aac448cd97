// tools/pvrnn/pvrnn_commands.hpp: the PV-RNN subcommands of the `dyad` CLI.
//
//   dyad train CONFIG.yaml [--resume] [--set key=value]...
//   dyad import-nrl MODEL_DIR --properties FILE --dataset DIR -o OUT.dpvrnn
//   dyad generate model MODEL --primitive N --steps T [-o CSV] [--seed S | --no-noise]
//   dyad generate dataset --out DIR
//   dyad regress MODEL TRAJECTORY.csv [-o OUT.csv] [--preset vcbot|reference] [--window W]
//                [--iterations N] [--optimizer adam|ceres] [--lr X --beta1 X --beta2 X]
//                [--meta-prior W0 W1] [--a-init zero|copy|prior] [--noise off|fixed|resample]
//                [--start-primitive P] [--seed S] [--budget-ms X]
//     Offline error regression (issue 4): one output row per executed step: step,
//     executed_x/y, intended_x/y (the intention for the next step), nelbo, reconstruction,
//     regulation, iterations, evaluations, time_ms; a first row (step -1) holds the intention
//     of step 0.
//
// Each subcommand's callback stores its process exit code in `exit_code`: 0 success,
// 1 runtime failure (I/O, training diverged), 2 bad input or usage.
#pragma once

namespace CLI {
class App;  // <CLI/CLI.hpp> is costly to compile: only the command files include it
}  // namespace CLI

namespace dyad::cli {

void AddPvrnnCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
