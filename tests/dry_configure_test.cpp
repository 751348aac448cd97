// Validation includes what components reject in Configure (DryConfigure): each problem placed at
// the param, the element inside a structured param, or the --set; all reported at once; nothing
// started. Uses the built-in plugins (human_synthetic, deliberator) and a tiny data set.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <dyad/catalog.hpp>
#include <dyad/graph.hpp>
#include <dyad/validate.hpp>

#include "plugin_catalog.hpp"

namespace dyad {
namespace {

namespace fs = std::filesystem;

// Three primitives of 5 steps, 2 DOF, in the NRL layout.
std::string TinyDataset() {
  const fs::path dir = fs::temp_directory_path() / ("dyad_dry_" + std::to_string(getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "dataset.d") << "samplingperiod=100\nnumbertimes=5\nnumberprims=3\n";
  for (int p = 0; p < 3; ++p) {
    std::ofstream f(dir / ("primitive_" + std::to_string(p) + "_0.csv"));
    for (int t = 0; t < 5; ++t) f << t + p << "," << -t << "\n";
  }
  return dir.string();
}

std::vector<Diagnostic> Validate(const std::string& yaml, const std::vector<std::string>& sets = {}) {
  std::vector<Diagnostic> diags;
  std::vector<Override> overrides;
  for (const auto& s : sets) overrides.push_back({s});
  Graph g = ParseGraph(yaml, "g.yaml", overrides, &diags);
  ResolvedGraph r = ValidateGraph(g, testing::BuiltPlugins(), &diags);
  DryConfigure(g, r, testing::BuiltPlugins(), &diags);
  return diags;
}

std::string Humans(const std::string& dataset) {
  return "graph: dry\nclock: stepped\ncomponents:\n"
         "  a:\n    type: human_synthetic\n    rate_hz: 10\n    params:\n      dataset: " + dataset + "\n"
         "      events:\n"
         "        - {start: 1, end: 3, primitive: 0}\n"
         "        - {start: 10, end: 5, primitive: 1}\n"    // line 11: end before start
         "    outputs: {out: ha}\n"
         "  b:\n    type: human_synthetic\n    rate_hz: 10\n    params:\n      dataset: " + dataset + "\n"
         "      events:\n"
         "        - {start: 1, end: 3, primitve: 2}\n"       // line 19: key typo
         "    outputs: {out: hb}\n";
}

TEST(DryConfigure, ComponentErrorsArePlacedAtTheElementAndReportedTogether) {
  const auto diags = Validate(Humans(TinyDataset()));
  ASSERT_EQ(diags.size(), 2u);
  EXPECT_EQ(diags[0].ToString(), "g.yaml:11:23: components.a.params.events[1].end = 5: must be > start (10)");
  EXPECT_EQ(diags[1].key, "components.b.params.events[0].primitve");
  EXPECT_EQ(diags[1].mark.line, 19);
  EXPECT_EQ(diags[1].mark.column, 30);  // the misspelt key itself
  EXPECT_NE(diags[1].message.find("unknown key"), std::string::npos) << diags[1].ToString();
}

TEST(DryConfigure, AFileSetOnTheCommandLineIsBlamedOnTheSet) {
  const std::string y = "graph: dry\nclock: stepped\ncomponents:\n"
                        "  mind: {type: deliberator, rate_hz: 10, params: {model: x.dpvrnn}, inputs: {executed: s}, outputs: {intention: i}}\n"
                        "topics:\n  s: {type: CartesianState}\n";
  const auto diags = Validate(y, {"mind.model=/nonexistent.dpvrnn"});
  ASSERT_EQ(diags.size(), 1u);
  EXPECT_EQ(diags[0].mark.file, "--set mind.model=/nonexistent.dpvrnn");
  EXPECT_EQ(diags[0].key, "components.mind.params.model");
  EXPECT_NE(diags[0].message.find("/nonexistent.dpvrnn"), std::string::npos) << diags[0].ToString();
}

// A process started on its own checks only its own components: another process's files live on
// its machine or are already open there (a launcher's child saw the recorder's file, just created
// by the recorder's process, as "exists" and refused to start).
TEST(DryConfigure, OnlyTheComponentsOfTheGivenProcessAreConfigured) {
  std::string y = Humans(TinyDataset());
  y.replace(y.find("clock: stepped"), 14, "clock: wall\nprocesses: {pa: {}, pb: {}}");
  y.replace(y.find("  a:\n    type: human_synthetic\n"), 31, "  a:\n    type: human_synthetic\n    process: pa\n");
  y.replace(y.find("  b:\n    type: human_synthetic\n"), 31, "  b:\n    type: human_synthetic\n    process: pb\n");
  std::vector<Diagnostic> diags;
  Graph g = ParseGraph(y, "g.yaml", {}, &diags);
  ResolvedGraph r = ValidateGraph(g, testing::BuiltPlugins(), &diags);
  ASSERT_TRUE(diags.empty()) << diags[0].ToString();
  DryConfigure(g, r, testing::BuiltPlugins(), &diags, {"pb"});
  ASSERT_EQ(diags.size(), 1u);
  EXPECT_EQ(diags[0].key, "components.b.params.events[0].primitve");
  diags.clear();
  DryConfigure(g, r, testing::BuiltPlugins(), &diags);  // the launcher: every component
  EXPECT_EQ(diags.size(), 2u);
}

TEST(DryConfigure, AComponentWithStructuralProblemsIsNotConfigured) {
  // A mistyped param is a structural problem: reported once, Configure not attempted.
  std::string y = Humans(TinyDataset());
  y.replace(y.find("rate_hz: 10"), 11, "rate_hz: 10\n    params_typo: 1");
  const auto diags = Validate(y);
  for (const auto& d : diags) EXPECT_NE(d.key.rfind("components.a.params.events", 0), 0u) << d.ToString();
}

TEST(GraphValidation, TriggerOnAnUnboundOptionalInputIsAnError) {
  const std::string y = "graph: t\nclock: stepped\ncomponents:\n"
                        "  src: {type: counter_source, rate_hz: 10, outputs: {out: count}}\n"
                        "  mix:\n    type: compliance_mixer\n    trigger: state\n"
                        "    inputs: {human: h, robot: r}\n    outputs: {command: c}\n"
                        "topics:\n  h: {type: HumanInput}\n  r: {type: Intention}\n";
  std::vector<Diagnostic> diags;
  Graph g = ParseGraph(y, "g.yaml", {}, &diags);
  ValidateGraph(g, testing::BuiltPlugins(), &diags);
  ASSERT_EQ(diags.size(), 1u) << diags[0].ToString();
  EXPECT_EQ(diags[0].ToString().rfind("g.yaml:7:14: components.mix.trigger: input 'state' is not bound", 0), 0u)
      << diags[0].ToString();
}

}  // namespace
}  // namespace dyad
