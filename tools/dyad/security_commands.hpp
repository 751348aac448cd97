// `dyad security init DIR --graph GRAPH`: the DDS Security keystore of a graph (keystore.hpp;
// what a secured graph is: dyad/security.hpp, docs/security.md).
#pragma once

namespace CLI {
class App;  // <CLI/CLI.hpp> is costly to compile: only the command files include it
}  // namespace CLI

namespace dyad::cli {

void AddSecurityCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
