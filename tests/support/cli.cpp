#include "dyad/testing/cli.hpp"

#include <gtest/gtest.h>

#include <CLI/CLI.hpp>

namespace dyad::testing {

CliRun RunCommand(void (*add_commands)(CLI::App& app, int& exit_code), std::vector<std::string> args) {
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
