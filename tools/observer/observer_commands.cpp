#include "observer_commands.hpp"

namespace dyad::cli {

void AddObserverCommands(CLI::App& /*app*/, int& /*exit_code*/) {}

}  // namespace dyad::cli
