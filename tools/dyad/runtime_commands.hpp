// `dyad validate | run | types | topics | hz`: the runtime's commands of the dyad CLI.
#pragma once

#include <functional>

#include <dyad/run.hpp>

namespace CLI {
class App;  // <CLI/CLI.hpp> is costly to compile: only the command files include it
}  // namespace CLI

namespace dyad::cli {

void AddRuntimeCommands(CLI::App& app, int& exit_code);

// `dyad run GRAPH [flags]` on `app`: once parsed, `on_run` gets the options (AddRuntimeCommands
// runs them: RunGraph). The launcher renders the same options back into these flags for its
// children (runtime/hosts/run_arguments.hpp); test/run_arguments_test.cpp checks the round trip.
CLI::App* AddRunCommand(CLI::App& app, std::function<void(const RunOptions&)> on_run);

}  // namespace dyad::cli
