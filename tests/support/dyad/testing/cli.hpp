// dyad/testing/cli.hpp: runs one command group of the `dyad` CLI in-process, capturing what it
// prints (test code only; link dyad_test_cli). CLI11 stays out of this header: it costs seconds
// of compile time in every file that includes it.
//
//   auto r = dyad::testing::RunCommand(dyad::cli::AddBagCommands, {"bag", "info", path});
//   EXPECT_EQ(r.code, 2) << r.err;
#pragma once

#include <string>
#include <vector>

namespace CLI {
class App;
}  // namespace CLI

namespace dyad::testing {

struct CliRun {
  int code = -1;  // the exit code the command stored (-1: it never ran)
  std::string out, err;
};

// `add_commands(app, exit_code)` registers the group, as tools/dyad/main.cpp does.
CliRun RunCommand(void (*add_commands)(CLI::App& app, int& exit_code), std::vector<std::string> args);

}  // namespace dyad::testing
