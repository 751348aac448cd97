// Composing graphs without copying them: `extends:` overlays and `--set C.type=T`. An overlay's
// keys merge over its base; each problem names the file (or --set) that wrote the key, and a
// relative path is relative to the file that wrote it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <unistd.h>

#include <dyad/catalog.hpp>
#include <dyad/graph.hpp>
#include <dyad/validate.hpp>

#include "plugin_catalog.hpp"

namespace dyad {
namespace {

namespace fs = std::filesystem;

// The lab's graph in base/, a participant's overlay in mine/ (a sibling folder).
class ExtendsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("dyad_extends_" + std::to_string(::getpid()));
    fs::create_directories(dir_ / "base");
    fs::create_directories(dir_ / "mine");
    Write("base/demo.yaml", R"(graph: demo
clock: stepped
plugins: [plugins]
components:
  src: {type: counter_source, rate_hz: 10, params: {noise: 1, limit: 5}, outputs: {out: count}}
  sink: {type: counter_sink, trigger: in, inputs: {in: count}, params: {file: out/sink.txt, expect: 3}}
  spare: {type: counter_sink, trigger: in, inputs: {in: count}}
)");
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  // Parses the overlay mine/NAME, validates it, returns every problem.
  const Graph& Load(const std::string& name, std::vector<Diagnostic>* diags, const std::vector<Override>& sets = {}) {
    graph_ = LoadGraph((dir_ / "mine" / name).string(), sets, diags);
    resolved_ = ValidateGraph(graph_, testing::BuiltPlugins(), diags);
    return graph_;
  }
  const ResolvedComponent& Resolved(const std::string& name) const {
    for (const auto& c : resolved_.components)
      if (c.config->name == name) return c;
    throw std::runtime_error("no component " + name);
  }

  fs::path dir_;
  Graph graph_;
  ResolvedGraph resolved_;
};

TEST_F(ExtendsTest, AnOverlayMergesItsKeysOverTheBaseAndPathsStayWithTheFileThatWroteThem) {
  Write("mine/my.yaml", R"(extends: ../base/demo.yaml
graph: mine
components:
  src: {params: {noise: 2}}
  spare: {params: {file: spare.txt}}
)");
  std::vector<Diagnostic> diags;
  const Graph& g = Load("my.yaml", &diags);
  ASSERT_TRUE(diags.empty()) << diags[0].ToString();
  EXPECT_EQ(g.name, "mine");
  EXPECT_EQ(g.clock, ClockMode::kStepped);  // the base's, untouched
  ASSERT_EQ(g.components.size(), 3u);
  EXPECT_DOUBLE_EQ(Resolved("src").params.Double("noise"), 2);
  EXPECT_EQ(Resolved("src").params.Int("limit"), 5);  // merged key by key
  const std::string base = fs::absolute(dir_ / "base").lexically_normal().string();
  const std::string mine = fs::absolute(dir_ / "mine").lexically_normal().string();
  EXPECT_EQ(Resolved("sink").params.String("file"), base + "/out/sink.txt");
  EXPECT_EQ(Resolved("spare").params.String("file"), mine + "/spare.txt");
  ASSERT_EQ(g.plugins.size(), 1u);
  EXPECT_EQ(g.plugins[0], base + "/plugins");
  // The recording keeps the graph as run, saying what it was made of.
  EXPECT_EQ(g.yaml_text.rfind("# the graph as run: " + (dir_ / "mine/my.yaml").string() + " extends " +
                                  (dir_ / "base/demo.yaml").string() + "\n",
                              0),
            0u)
      << g.yaml_text;
  const YAML::Node run = YAML::Load(g.yaml_text);
  EXPECT_EQ(run["graph"].as<std::string>(), "mine");
  EXPECT_FALSE(run["extends"]);
  EXPECT_EQ(run["components"]["src"]["params"]["limit"].as<int>(), 5);
}

TEST_F(ExtendsTest, ResetRemovesAKeyAndOverrideReplacesAMapInsteadOfMergingIt) {
  Write("mine/my.yaml", R"(extends: ../base/demo.yaml
components:
  spare: !reset
  sink: {params: !override {expect: 9}}
)");
  std::vector<Diagnostic> diags;
  const Graph& g = Load("my.yaml", &diags);
  ASSERT_TRUE(diags.empty()) << diags[0].ToString();
  EXPECT_EQ(g.FindComponent("spare"), nullptr);
  EXPECT_EQ(Resolved("sink").params.Int("expect"), 9);
  EXPECT_EQ(Resolved("sink").params.String("file"), "");  // the base's file is gone with its map
}

// A chain: each file's problems at its own lines.
TEST_F(ExtendsTest, ProblemsNameTheFileAndLineThatWroteTheKey) {
  Write("mine/middle.yaml", "extends: ../base/demo.yaml\ncomponents:\n  src: {params: {noise: -1}}\n");
  Write("mine/my.yaml", "extends: middle.yaml\ncomponents:\n  sink: {params: {expect: many}}\n  src: {rate: 3}\n");
  std::vector<Diagnostic> diags;
  ValidateGraph(LoadGraph((dir_ / "mine/my.yaml").string(), {}, &diags), testing::BuiltPlugins(), &diags);
  std::string all;
  for (const auto& d : diags) all += d.ToString() + "\n";
  const std::string my = (dir_ / "mine/my.yaml").string(), middle = (dir_ / "mine/middle.yaml").string();
  EXPECT_NE(all.find(my + ":4:9: components.src.rate: unknown key"), std::string::npos) << all;
  EXPECT_NE(all.find(my + ":3:27: components.sink.params.expect"), std::string::npos) << all;
  EXPECT_NE(all.find(middle + ":3:25: components.src.params.noise"), std::string::npos) << all;
}

TEST_F(ExtendsTest, ABrokenChainIsAnErrorAtItsExtendsLine) {
  const std::pair<const char*, const char*> cases[] = {
      {"extends: nowhere.yaml\n", "cannot open"},
      {"extends: [a, b]\n", "must be the path of the graph file"},
      {"extends: my.yaml\n", "goes round in a circle"},
  };
  for (const auto& [text, why] : cases) {
    Write("mine/my.yaml", std::string("graph: x\n") + text);
    std::vector<Diagnostic> diags;
    LoadGraph((dir_ / "mine/my.yaml").string(), {}, &diags);
    ASSERT_FALSE(diags.empty()) << text;
    EXPECT_EQ(diags[0].key, "extends");
    EXPECT_EQ(diags[0].mark.file, (dir_ / "mine/my.yaml").string());
    EXPECT_EQ(diags[0].mark.line, 2);
    EXPECT_NE(diags[0].message.find(why), std::string::npos) << diags[0].ToString();
  }
  Write("mine/broken.yaml", "components: {a: [}\n");
  Write("mine/my.yaml", "extends: broken.yaml\n");
  std::vector<Diagnostic> diags;
  LoadGraph((dir_ / "mine/my.yaml").string(), {}, &diags);
  ASSERT_FALSE(diags.empty());
  EXPECT_EQ(diags[0].mark.file, (dir_ / "mine/broken.yaml").string());
  EXPECT_NE(diags[0].message.find("YAML syntax error"), std::string::npos);
}

// `--set C.type=T` swaps a component's type (it used to be read as a parameter named "type"),
// and the bindings and a component's own keys are set the same way.
TEST_F(ExtendsTest, ASetWritesAComponentsTypeBindingsAndOwnKeys) {
  Write("mine/my.yaml", "extends: ../base/demo.yaml\n");
  std::vector<Diagnostic> diags;
  const Graph& g = Load("my.yaml", &diags, {{"spare.type=counter_source"}, {"spare.rate_hz=5"}, {"src.outputs.out=other"}});
  ASSERT_FALSE(diags.empty());
  EXPECT_EQ(g.FindComponent("spare")->type, "counter_source");
  EXPECT_EQ(g.FindComponent("spare")->rate_hz, 5);
  EXPECT_EQ(g.FindComponent("src")->outputs.at(0).topic, "other");
  // counter_source has no input `in`: reported at the base's line, where the binding is written.
  std::string all;
  for (const auto& d : diags) all += d.ToString() + "\n";
  EXPECT_NE(all.find((dir_ / "base/demo.yaml").string() + ":7:"), std::string::npos) << all;

  // All of a component's params at once: the old ones are gone.
  diags.clear();
  Load("my.yaml", &diags, {{"sink.params={expect: 4}"}});
  ASSERT_TRUE(diags.empty()) << diags[0].ToString();
  EXPECT_EQ(Resolved("sink").params.Int("expect"), 4);
  EXPECT_EQ(Resolved("sink").params.String("file"), "");

  diags.clear();
  LoadGraph((dir_ / "mine/my.yaml").string(), {{"spare.rate_hz=fast"}}, &diags);
  ASSERT_EQ(diags.size(), 1u);
  EXPECT_EQ(diags[0].mark.ToString(), "--set spare.rate_hz=fast");
  EXPECT_EQ(diags[0].key, "components.spare.rate_hz");
  diags.clear();
  LoadGraph((dir_ / "mine/my.yaml").string(), {{"nobody.type=counter_sink"}}, &diags);
  ASSERT_EQ(diags.size(), 1u);
  EXPECT_NE(diags[0].message.find("no such component"), std::string::npos);
}

// A --set that goes through a list or a scalar cannot be placed: an error at the --set (it was
// dropped without a word, the file being fine there).
TEST_F(ExtendsTest, ASetThroughAListOrAScalarIsAnErrorAtTheSet) {
  Write("mine/net.yaml", "extends: ../base/demo.yaml\nnetwork: {discovery: peers, peers: [10.0.0.9], hosts: {lab: 10.0.0.1}}\n");
  for (const auto& [set, says] : std::vector<std::pair<std::string, std::string>>{
           {"network.peers.0=10.0.0.8", "cannot set '0' inside network.peers, which is a list: set network.peers as a whole"},
           {"network.hosts.lab.port=7400", "cannot set 'port' inside network.hosts.lab, which is a scalar"}}) {
    std::vector<Diagnostic> diags;
    const Graph g = LoadGraph((dir_ / "mine/net.yaml").string(), {{set}}, &diags);
    ASSERT_EQ(diags.size(), 1u) << set;
    EXPECT_EQ(diags[0].mark.ToString(), "--set " + set);
    EXPECT_NE(diags[0].message.find(says), std::string::npos) << diags[0].ToString();
    EXPECT_EQ(g.network.peers, std::vector<std::string>{"10.0.0.9"});  // the file's value stands
  }
}

}  // namespace
}  // namespace dyad
