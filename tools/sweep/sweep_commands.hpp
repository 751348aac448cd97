// `dyad sweep SWEEP.yaml`: a grid of simulated experiments on every core (docs/sweep.md).
#pragma once

#include <CLI/CLI.hpp>

namespace dyad::cli {

void AddSweepCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
