// `dyad study ...`: a study with people: its plan (docs/study.md).
#pragma once

namespace CLI {
class App;  // <CLI/CLI.hpp> is costly to compile: only the command files include it
}  // namespace CLI

namespace dyad::cli {

void AddStudyCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
