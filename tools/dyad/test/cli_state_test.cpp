// The dyad CLI keeps no state between invocations in one process (options used to live in
// function statics: a second in-process `dyad run` inherited the first's --set).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "dyad/testing/cli.hpp"
#include "introspection_commands.hpp"
#include "runtime_commands.hpp"

namespace dyad::cli {
namespace {

TEST(CliState, ASecondInvocationDoesNotInheritTheFirstsOptions) {
  const auto graph = std::filesystem::temp_directory_path() / ("dyad_cli_state_" + std::to_string(getpid()) + ".yaml");
  std::ofstream(graph) << "graph: s\nclock: stepped\ncomponents:\n"
                          "  src: {type: counter_source, rate_hz: 10, outputs: {out: count}}\n"
                          "  sink: {type: counter_sink, trigger: in, inputs: {in: count}}\n";
  auto bad = dyad::testing::RunCommand(AddRuntimeCommands, {"validate", graph.string(), "--set", "src.noise=-1"});
  EXPECT_EQ(bad.code, 2) << bad.err;
  auto good = dyad::testing::RunCommand(AddRuntimeCommands, {"validate", graph.string()});
  EXPECT_EQ(good.code, 0) << "the --set of the first invocation leaked into the second:\n" << good.err;
  auto run = dyad::testing::RunCommand(AddRuntimeCommands, {"run", graph.string(), "--steps", "3", "--quiet"});
  EXPECT_EQ(run.code, 0) << run.err;
  std::filesystem::remove(graph);
}

TEST(CliState, IntrospectionOptionsArePerInvocation) {
  // --domain 231 (nothing there) first; the second invocation's default wait must not be 0.3 s.
  auto first = dyad::testing::RunCommand(AddIntrospectionCommands, {"topics", "--domain", "231", "--wait", "0.3"});
  EXPECT_EQ(first.code, 1);
  EXPECT_NE(first.err.find("within 0.3 s"), std::string::npos) << first.err;
  auto second = dyad::testing::RunCommand(AddIntrospectionCommands, {"echo", "no/such/topic", "--domain", "231"});
  EXPECT_EQ(second.code, 1);
  EXPECT_NE(second.err.find("on domain 231 within 5 s"), std::string::npos) << "inherited --wait: " << second.err;
}

}  // namespace
}  // namespace dyad::cli

namespace dyad::cli {
namespace {

// `dyad types` prints ranges exactly: an integer bound as an integer, not in %g notation.
TEST(CliTypes, RangesArePrintedExactly) {
  auto r = dyad::testing::RunCommand(AddRuntimeCommands, {"types"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("range 1024..1073741824"), std::string::npos) << r.out;  // recorder's chunk_size
  EXPECT_EQ(r.out.find("e+"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("range 1e-06..inf"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace dyad::cli
