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

// A run that fails before any step says why, and prints no timing table of zeros above it; a
// run that stepped keeps its table even when it fails.
TEST(CliRun, ARunThatNeverSteppedPrintsNoTableOfZeros) {
  const auto graph = std::filesystem::temp_directory_path() / ("dyad_cli_zeros_" + std::to_string(getpid()) + ".yaml");
  std::ofstream(graph) << "graph: z\nclock: stepped\ncomponents:\n"
                          "  src: {type: counter_source, rate_hz: 10, outputs: {out: count}}\n"
                          "  sink: {type: counter_sink, trigger: in, inputs: {in: count}, params: {file: /nonexistent/dir/x.txt}}\n";
  auto failed = dyad::testing::RunCommand(AddRuntimeCommands, {"run", graph.string(), "--steps", "3"});
  EXPECT_NE(failed.code, 0);
  EXPECT_NE(failed.err.find("sink: activate failed"), std::string::npos) << failed.err;
  EXPECT_EQ(failed.out.find("timing (process"), std::string::npos) << failed.out;
  std::ofstream(graph) << "graph: z\nclock: stepped\ncomponents:\n"
                          "  src: {type: counter_source, rate_hz: 10, outputs: {out: count}}\n"
                          "  sink: {type: counter_sink, trigger: in, inputs: {in: count}}\n";
  auto ran = dyad::testing::RunCommand(AddRuntimeCommands, {"run", graph.string(), "--steps", "3"});
  EXPECT_EQ(ran.code, 0) << ran.err;
  EXPECT_NE(ran.out.find("timing (process main)"), std::string::npos) << ran.out;
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

namespace dyad::cli {
namespace {

// `dyad types --markdown NAME` is the block docs/components.md embeds (tools/docs.py); an unknown
// name is an error, not an empty block.
TEST(CliTypes, MarkdownReferenceOfOneTypeAndOfTheMessages) {
  auto r = dyad::testing::RunCommand(AddRuntimeCommands, {"types", "--markdown", "counter_sink"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("<!-- BEGIN dyad types --markdown counter_sink ", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("| input `in` | Counter |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| `file` | string (path) | `\"\"` |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("<!-- END dyad types --markdown counter_sink -->"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("counter_source"), std::string::npos) << r.out;

  auto unknown = dyad::testing::RunCommand(AddRuntimeCommands, {"types", "--markdown", "no_such_type"});
  EXPECT_EQ(unknown.code, 2);
  EXPECT_NE(unknown.err.find("no component type 'no_such_type'"), std::string::npos) << unknown.err;

  auto messages = dyad::testing::RunCommand(AddRuntimeCommands, {"types", "--messages", "--markdown"});
  ASSERT_EQ(messages.code, 0) << messages.err;
  // Fields with their IDL type and the comment of their line, from idl/human.idl.
  EXPECT_NE(messages.out.find("| `engaged` | `boolean` | true while the human holds the robot (intervenes) |"),
            std::string::npos) << messages.out;
  EXPECT_NE(messages.out.find("| `stamp_ns` | `long long` |"), std::string::npos) << messages.out;
  EXPECT_NE(messages.out.find("| `human` | `sequence<double>` |"), std::string::npos) << messages.out;
}

}  // namespace
}  // namespace dyad::cli

namespace dyad::cli {
namespace {

// `dyad echo --graph` with a graph that cannot be read says where and exits 2 (no discovery wait).
TEST(CliIntrospection, EchoWithAnUnreadableGraphNamesItAndExits2) {
  auto r = dyad::testing::RunCommand(AddIntrospectionCommands, {"echo", "t", "--graph", "/nonexistent/g.yaml"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("/nonexistent/g.yaml"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dyad::cli
