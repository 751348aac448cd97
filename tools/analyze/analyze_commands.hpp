// tools/analyze/analyze_commands.hpp: the analysis subcommands of the `dyad` CLI.
//
// Each subcommand's callback stores its process exit code in `exit_code`: 0 success,
// 1 runtime failure, 2 bad input or usage.
#pragma once

#include <CLI/CLI.hpp>

namespace dyad::cli {

void AddAnalyzeCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
