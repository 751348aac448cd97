// `dyad record` and `dyad bag play`: a recorder or a replay visiting a running graph as a guest
// (dyad/guest.hpp). `bag play` joins the `bag` command group, so this is added after it.
#pragma once

#include <string>

namespace CLI {
class App;  // <CLI/CLI.hpp> is costly to compile: only the command files include it
}  // namespace CLI

namespace dyad::cli {

void AddGuestCommands(CLI::App& app, int& exit_code);

// Who `dyad param` says made a parameter change: "dyad param (USER@HOST)". USER is $USER; when it
// is unset or empty, the account name of the real user id in the password database (getpwuid);
// "?" only when neither says.
std::string ParamRequester();

}  // namespace dyad::cli
