// tools/pvrnn/pvrnn_commands.hpp: the PV-RNN subcommands of the `dyad` CLI.
//
//   dyad train CONFIG.yaml [--resume] [--set key=value]...
//   dyad import-nrl MODEL_DIR --properties FILE --dataset DIR -o OUT.dpvrnn
//   dyad generate model MODEL --primitive N --steps T [-o CSV] [--seed S | --no-noise]
//   dyad generate dataset --out DIR
//
// Each subcommand's callback stores its process exit code in `exit_code`: 0 success,
// 1 runtime failure (I/O, training diverged), 2 bad input or usage.
#pragma once

#include <CLI/CLI.hpp>

namespace dyad::cli {

void AddPvrnnCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
