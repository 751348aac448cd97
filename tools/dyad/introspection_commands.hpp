// `dyad topics | echo | hz`: look at a running experiment from outside.
#pragma once

#include <CLI/CLI.hpp>

namespace dyad::cli {

void AddIntrospectionCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
