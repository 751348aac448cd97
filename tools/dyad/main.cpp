// The dyad command line: one executable, one subcommand per job. Each command group lives in
// its own library and adds its subcommands here.
#include <CLI/CLI.hpp>

#include <csignal>
#include <iostream>

#include "analyze_commands.hpp"
#include "bag_commands.hpp"
#include "introspection_commands.hpp"
#include "observer_commands.hpp"
#include "pvrnn_commands.hpp"
#include "runtime_commands.hpp"
#include "security_commands.hpp"
#include "sweep_commands.hpp"

int main(int argc, char** argv) {
  // A closed output (`dyad echo T | head`) makes writes fail instead of killing the process, so
  // every command ends cleanly (DDS participants deleted, files closed).
  std::signal(SIGPIPE, SIG_IGN);
  CLI::App app{"dyad: human-robot interaction experiments as graphs of components over DDS"};
  app.require_subcommand(1);
  app.set_help_all_flag("--help-all", "Show every subcommand's help");
  int exit_code = 0;
  dyad::cli::AddRuntimeCommands(app, exit_code);
  dyad::cli::AddIntrospectionCommands(app, exit_code);
  dyad::cli::AddSecurityCommands(app, exit_code);
  dyad::cli::AddBagCommands(app, exit_code);
  dyad::cli::AddPvrnnCommands(app, exit_code);
  dyad::cli::AddObserverCommands(app, exit_code);
  dyad::cli::AddAnalyzeCommands(app, exit_code);
  dyad::cli::AddSweepCommands(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;  // usage errors are bad input
  }
  return exit_code;
}
