#include "analyze_commands.hpp"

namespace dyad::cli {

void AddAnalyzeCommands(CLI::App& /*app*/, int& /*exit_code*/) {}

}  // namespace dyad::cli
