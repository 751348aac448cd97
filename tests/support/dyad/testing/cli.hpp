// dyad/testing/cli.hpp: runs one command group of the `dyad` CLI in-process, capturing what it
// prints (test code only; needs GoogleTest and CLI11).
//
//   auto r = dyad::testing::RunCommand(dyad::cli::AddBagCommands, {"bag", "info", path});
//   EXPECT_EQ(r.code, 2) << r.err;
#pragma once

#include <gtest/gtest.h>

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace dyad::testing {

struct CliRun {
  int code = -1;  // the exit code the command stored (-1: it never ran)
  std::string out, err;
};

// `add_commands(app, exit_code)` registers the group, as tools/dyad/main.cpp does.
template <class AddCommands>
CliRun RunCommand(AddCommands add_commands, std::vector<std::string> args) {
  CLI::App app{"dyad"};
  CliRun r;
  add_commands(app, r.code);
  args.insert(args.begin(), "dyad");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  app.parse(static_cast<int>(argv.size()), argv.data());
  r.err = ::testing::internal::GetCapturedStderr();
  r.out = ::testing::internal::GetCapturedStdout();
  return r;
}

}  // namespace dyad::testing
