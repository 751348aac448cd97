// `dyad sweep SWEEP.yaml`: a grid of simulated experiments on every core (docs/sweep.md).
#pragma once

namespace CLI {
class App;  // <CLI/CLI.hpp> is costly to compile: only the command files include it
}  // namespace CLI

namespace dyad::cli {

void AddSweepCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
