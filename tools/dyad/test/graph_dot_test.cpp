// `dyad graph`: the demo and the split demo drawn; the DOT holds every component and topic,
// processes and hosts as clusters, and Graphviz's own dot renders it without a complaint.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "dyad/graph.hpp"
#include "dyad/testing/cli.hpp"
#include "runtime_commands.hpp"

namespace dyad::cli {
namespace {

namespace fs = std::filesystem;

bool HaveDot() { return std::system("command -v dot > /dev/null 2>&1") == 0; }

std::string Slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class GraphDot : public ::testing::TestWithParam<const char*> {};

TEST_P(GraphDot, HoldsEveryComponentAndTopicAndRendersWithDot) {
  const std::string path = std::string(DYAD_SOURCE_DIR) + "/configs/" + GetParam();
  auto r = dyad::testing::RunCommand(AddRuntimeCommands, {"graph", path});
  ASSERT_EQ(r.code, 0) << r.err;
  std::vector<Diagnostic> ignored;
  const Graph g = LoadGraph(path, {}, &ignored);
  ASSERT_FALSE(g.components.empty());
  for (const auto& c : g.components) {
    EXPECT_NE(r.out.find("\"c:" + c.name + "\" [shape=box"), std::string::npos) << c.name << "\n" << r.out;
    for (const auto& b : c.outputs)
      EXPECT_NE(r.out.find("\"c:" + c.name + "\" -> \"t:" + b.topic + "\" [label=\"" + b.port + "\"]"), std::string::npos) << r.out;
    for (const auto& b : c.inputs)
      EXPECT_NE(r.out.find("\"t:" + b.topic + "\" -> \"c:" + c.name + "\" [label=\"" + b.port + "\"]"), std::string::npos) << r.out;
  }
  if (g.ProcessNames().size() > 1) {
    for (const auto& p : g.ProcessNames()) EXPECT_NE(r.out.find("\"cluster_process_" + p + "\""), std::string::npos) << r.out;
  }
  for (const auto& p : g.processes) {
    if (p.host.empty()) continue;
    EXPECT_NE(r.out.find("\"cluster_host_" + p.host + "\""), std::string::npos) << r.out;
  }
  EXPECT_NE(r.out.find("\\nCartesianState\""), std::string::npos) << "topic types in the labels:\n" << r.out;

  if (!HaveDot()) GTEST_SKIP() << "Graphviz's dot is not installed (tools/setup.sh installs graphviz)";
  const fs::path svg = fs::temp_directory_path() / ("dyad_graph_" + std::to_string(getpid()) + ".svg");
  auto drawn = dyad::testing::RunCommand(AddRuntimeCommands, {"graph", path, "--svg", svg.string()});
  ASSERT_EQ(drawn.code, 0) << drawn.err;
  EXPECT_EQ(drawn.err, "") << "dot complained";
  const std::string text = Slurp(svg);
  EXPECT_NE(text.find("<svg"), std::string::npos);
  for (const auto& c : g.components) EXPECT_NE(text.find(">" + c.name + "</text>"), std::string::npos) << c.name;
  EXPECT_FALSE(fs::exists(svg.string() + ".dot"));
  fs::remove(svg);
}

INSTANTIATE_TEST_SUITE_P(Configs, GraphDot, ::testing::Values("demo.yaml", "split.yaml"));

TEST(GraphDotErrors, ABadGraphIsRefusedAndNothingIsDrawn) {
  const fs::path g = fs::temp_directory_path() / ("dyad_graph_bad_" + std::to_string(getpid()) + ".yaml");
  std::ofstream(g) << "graph: bad\ncomponents:\n  src: {type: no_such_type, rate_hz: 10}\n";
  auto r = dyad::testing::RunCommand(AddRuntimeCommands, {"graph", g.string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no_such_type"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("nothing was drawn"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  fs::remove(g);
}

// A topic declared under `topics:` and bound to no port is drawn, and a recorder has an edge from
// each topic it records (its params.topics), the unbound one too.
TEST(GraphDotRecorder, DrawsUnboundTopicsAndWhatTheRecorderRecords) {
  const fs::path g = fs::temp_directory_path() / ("dyad_graph_rec_" + std::to_string(getpid()) + ".yaml");
  const fs::path mcap = fs::temp_directory_path() / ("dyad_graph_rec_" + std::to_string(getpid()) + ".mcap");
  std::ofstream(g) << "graph: drawn\n"
                      "components:\n"
                      "  src: {type: counter_source, rate_hz: 10, outputs: {out: count}}\n"
                      "  rec: {type: recorder, rate_hz: 1, params: {file: \"" << mcap.string() << "\", topics: [count, spare]}}\n"
                      "topics:\n"
                      "  spare: {type: Counter}\n";
  auto r = dyad::testing::RunCommand(AddRuntimeCommands, {"graph", g.string()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"t:spare\" [shape=ellipse, label=\"spare\\nCounter\"]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"t:count\" -> \"c:rec\" [label=\"records\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"t:spare\" -> \"c:rec\" [label=\"records\""), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("\"c:rec\" ->"), std::string::npos) << "a recorder writes no topic of the graph\n" << r.out;
  fs::remove(g);
  fs::remove(mcap);
}

}  // namespace
}  // namespace dyad::cli
