// tools/observer/observer_commands.hpp: the observer subcommands of the `dyad` CLI.
//
// Each subcommand's callback stores its process exit code in `exit_code`: 0 success,
// 1 runtime failure, 2 bad input or usage.
#pragma once

namespace CLI {
class App;  // <CLI/CLI.hpp> is costly to compile: only the command files include it
}  // namespace CLI

namespace dyad::cli {

void AddObserverCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
