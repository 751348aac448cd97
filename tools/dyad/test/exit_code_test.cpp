// The exit codes of every `dyad` command, one table (tools/support/exit_code.hpp): README.md shows
// the same rows, the runtime's codes (dyad run, the watchers, dyad train) are of it, and a usage
// error exits 2 like any other bad input.
#include <gtest/gtest.h>
#include <signal.h>

#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "dyad/interrupt.hpp"
#include "dyad/run.hpp"
#include "dyad/testing/cli.hpp"
#include "exit_code.hpp"
#include "runtime_commands.hpp"

namespace dyad::tools {
namespace {

std::string Readme() {
  std::ifstream in(std::string(DYAD_SOURCE_DIR) + "/README.md");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(ExitCodes, TheReadmeTableIsTheHeadersTable) {
  const std::string readme = Readme();
  const size_t section = readme.find("\n### Exit codes\n");
  ASSERT_NE(section, std::string::npos) << "README.md has no '### Exit codes' section";
  const std::string rest = readme.substr(section + 1);
  const std::string table = rest.substr(0, rest.find("\n#"));
  const std::regex row_start("\n\\| [0-9]+ \\|");
  int rows = 0;
  for (std::sregex_iterator i(table.begin(), table.end(), row_start), end; i != end; ++i) ++rows;
  EXPECT_EQ(rows, static_cast<int>(std::size(kExitCodes))) << table;
  for (const ExitCodeRow& row : kExitCodes) {
    const std::string line = "\n| " + std::to_string(Code(row.code)) + " | " + std::string(row.meaning) + " |";
    EXPECT_NE(table.find(line), std::string::npos) << "README.md's table lacks the row\n" << line << "\nin\n" << table;
  }
}

TEST(ExitCodes, TheRuntimesCodesAreOfTheTable) {
  EXPECT_EQ(ExitCodeOf(Status::OK()), Code(ExitCode::kOk));
  for (const Status& bad : {Status::InvalidArgument("x"), Status::NotFound("x"), Status::DataLoss("x")})
    EXPECT_EQ(ExitCodeOf(bad), Code(ExitCode::kBadInput)) << bad.ToString();
  for (const Status& failed : {Status::IOError("x"), Status::Internal("x"), Status::FailedPrecondition("x")})
    EXPECT_EQ(ExitCodeOf(failed), Code(ExitCode::kFailure)) << failed.ToString();
  EXPECT_EQ(ExitCodeForSignal(SIGINT), Code(ExitCode::kInterrupted));
  EXPECT_EQ(ExitCodeForSignal(SIGTERM), Code(ExitCode::kTerminated));
  EXPECT_EQ(ForSignal(SIGINT), ExitCode::kInterrupted);
  EXPECT_EQ(ForSignal(SIGTERM), ExitCode::kTerminated);
}

// Bad input on the command line and in a file it names: 2 both (the runtime's commands here).
TEST(ExitCodes, BadInputExitsTwo) {
  auto no_file = dyad::testing::RunCommand(dyad::cli::AddRuntimeCommands, {"validate", "/nonexistent/g.yaml"});
  EXPECT_EQ(no_file.code, Code(ExitCode::kBadInput)) << no_file.err;
  auto no_type = dyad::testing::RunCommand(dyad::cli::AddRuntimeCommands, {"types", "no_such_type"});
  EXPECT_EQ(no_type.code, Code(ExitCode::kBadInput)) << no_type.err;
}

}  // namespace
}  // namespace dyad::tools
