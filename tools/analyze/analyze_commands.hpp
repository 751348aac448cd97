// tools/analyze/analyze_commands.hpp: the analysis subcommand of the `dyad` CLI.
//
//   dyad analyze RECORDING.mcap [-o DIR] [--dataset DIR] [--no-plots]
//
// Writes a report folder (see report_writer.hpp): report.md with the events table and the
// observer's confusion on the human's traces, CSV tables, and PNG plots drawn by
// share/dyad/plot_report.py (python3-matplotlib). Default DIR: RECORDING without ".mcap" + "_report".
// Exit code (stored in `exit_code`): 0 success, 1 runtime failure (plots), 2 bad input.
#pragma once

namespace CLI {
class App;  // <CLI/CLI.hpp> is costly to compile: only the command files include it
}  // namespace CLI

namespace dyad::cli {

void AddAnalyzeCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
