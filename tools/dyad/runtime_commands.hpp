// `dyad validate | run | types | topics | hz`: the runtime's commands of the dyad CLI.
#pragma once

#include <CLI/CLI.hpp>

namespace dyad::cli {

void AddRuntimeCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
