// The launcher renders RunOptions back into `dyad run` flags for its children
// (runtime/hosts/run_arguments.hpp); the CLI parses them (AddRunCommand). What one writes, the
// other must read back as it was.
#include "hosts/run_arguments.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <optional>

#include <CLI/CLI.hpp>

#include "dyad/testing/cli.hpp"
#include "runtime_commands.hpp"

namespace dyad::cli {
namespace {

// `dyad` + args, parsed by the `run` command alone; the options it would have run.
std::optional<RunOptions> Parse(std::vector<std::string> args) {
  CLI::App app{"dyad"};
  std::optional<RunOptions> parsed;
  AddRunCommand(app, [&parsed](const RunOptions& options) { parsed = options; });
  args.insert(args.begin(), "dyad");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  app.parse(static_cast<int>(argv.size()), argv.data());
  return parsed;
}

// Every field that is a flag (`executable` is not one).
void ExpectSameFlags(const RunOptions& a, const RunOptions& b) {
  EXPECT_EQ(a.graph_path, b.graph_path);
  ASSERT_EQ(a.overrides.size(), b.overrides.size());
  for (size_t i = 0; i < a.overrides.size(); ++i) EXPECT_EQ(a.overrides[i].text, b.overrides[i].text);
  EXPECT_EQ(a.process, b.process);
  EXPECT_EQ(a.host, b.host);
  EXPECT_EQ(a.logs_dir, b.logs_dir);
  EXPECT_EQ(a.duration_s, b.duration_s);
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.stats_period_s, b.stats_period_s);
  EXPECT_EQ(a.plugin_paths, b.plugin_paths);
  EXPECT_EQ(a.quiet, b.quiet);
  EXPECT_EQ(a.run_id, b.run_id);
  EXPECT_EQ(a.strict, b.strict);
  EXPECT_EQ(a.restart_count, b.restart_count);
}

TEST(RunArguments, EveryOptionParsesBackAsItWas) {
  RunOptions o;
  o.graph_path = "configs/split.yaml";
  o.overrides = {Override{"src.noise=6"}, Override{"processes.mind.restart=never"}};
  o.process = "mind";
  o.host = "lab";
  o.logs_dir = "out/logs";
  o.duration_s = 1e-7;  // exactly, not rounded to 0
  o.steps = 12345678901234ULL;
  o.stats_period_s = 0.1;
  o.plugin_paths = {"a.so", "plugins/"};
  o.quiet = true;
  o.run_id = "3f2a9c01";
  o.strict = true;
  o.restart_count = 2;
  const auto parsed = Parse(RunArguments(o));
  ASSERT_TRUE(parsed.has_value());
  ExpectSameFlags(o, *parsed);
}

TEST(RunArguments, DefaultsRenderNoFlagAndParseBackToTheDefaults) {
  RunOptions o;
  o.graph_path = "g.yaml";
  EXPECT_EQ(RunArguments(o), (std::vector<std::string>{"run", "g.yaml"}));
  const auto parsed = Parse(RunArguments(o));
  ASSERT_TRUE(parsed.has_value());
  ExpectSameFlags(o, *parsed);
  EXPECT_EQ(parsed->executable, "/proc/self/exe");
}

TEST(RunArguments, TheRestartCountIsAHiddenFlag) {
  CLI::App app{"dyad"};
  CLI::App* run = AddRunCommand(app, [](const RunOptions&) {});
  EXPECT_EQ(run->help().find("--restart-count"), std::string::npos) << run->help();
  EXPECT_NE(run->help().find("--process"), std::string::npos);
}

TEST(RunArguments, TheRestartCountIsOnlyForAProcessAndNeverNegative) {
  const auto graph = std::filesystem::temp_directory_path() / ("dyad_restart_count_" + std::to_string(getpid()) + ".yaml");
  std::ofstream(graph) << "graph: s\nclock: stepped\ncomponents:\n"
                          "  src: {type: counter_source, rate_hz: 10, outputs: {out: count}}\n"
                          "  sink: {type: counter_sink, trigger: in, inputs: {in: count}}\n";
  auto launcher = dyad::testing::RunCommand(AddRuntimeCommands, {"run", graph.string(), "--steps", "3", "--restart-count", "1"});
  EXPECT_EQ(launcher.code, 2);
  EXPECT_NE(launcher.err.find("--restart-count 1: only with --process"), std::string::npos) << launcher.err;
  auto negative = dyad::testing::RunCommand(
      AddRuntimeCommands, {"run", graph.string(), "--process", "main", "--steps", "3", "--restart-count=-1"});
  EXPECT_EQ(negative.code, 2);
  EXPECT_NE(negative.err.find("--restart-count -1: must be >= 0"), std::string::npos) << negative.err;
  auto restarted = dyad::testing::RunCommand(
      AddRuntimeCommands, {"run", graph.string(), "--process", "main", "--steps", "3", "--quiet", "--restart-count", "1"});
  EXPECT_EQ(restarted.code, 0) << restarted.err;
  std::filesystem::remove(graph);
}

}  // namespace
}  // namespace dyad::cli
