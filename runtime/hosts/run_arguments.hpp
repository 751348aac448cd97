// RunArguments — RunOptions rendered back into `dyad run` arguments (internal to the runtime):
// what the launcher gives its children (`dyad run GRAPH --process P --restart-count N ...`).
//
// The one place that knows the flags besides their parser (tools/dyad/runtime_commands.cpp,
// AddRunCommand); tools/dyad/test/run_arguments_test.cpp parses what this renders and checks
// that every option comes back as it was. A field at its default is left out; doubles are
// written with 17 significant digits (1e-07 stays 1e-07). `executable` is no flag (it is how
// the launcher finds dyad) and is not rendered.
#pragma once

#include <string>
#include <vector>

#include <dyad/run.hpp>

namespace dyad {

// {"run", graph_path, flags...}: argv without the program's name.
std::vector<std::string> RunArguments(const RunOptions& options);

}  // namespace dyad
