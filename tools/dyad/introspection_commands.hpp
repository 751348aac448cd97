// `dyad topics | echo | hz`: look at a running experiment from outside.
#pragma once

namespace CLI {
class App;  // <CLI/CLI.hpp> is costly to compile: only the command files include it
}  // namespace CLI

namespace dyad::cli {

void AddIntrospectionCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
