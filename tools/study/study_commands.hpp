// `dyad study ...`: a study with people: its plan (docs/study.md).
#pragma once

#include <CLI/CLI.hpp>

namespace dyad::cli {

void AddStudyCommands(CLI::App& app, int& exit_code);

}  // namespace dyad::cli
