// `dyad record` and `dyad bag play`: a recorder or a replay visiting a running graph as a guest
// (dyad/guest.hpp). `bag play` joins the `bag` command group, so this is added after it.
#pragma once

namespace CLI {
class App;  // <CLI/CLI.hpp> is costly to compile: only the command files include it
}  // namespace CLI

namespace dyad::cli {

void AddGuestCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
