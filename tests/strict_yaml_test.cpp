// The strict YAML reader every format reads with (dyad/strict_yaml.hpp): each problem once, at
// its file:line:col or its --set, with the wording the graph and training config messages pin.
#include "dyad/strict_yaml.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace dyad {
namespace {

// The problems as "position: key: message" lines.
std::vector<std::string> Lines(const std::vector<Diagnostic>& problems) {
  std::vector<std::string> out;
  for (const Diagnostic& d : problems) out.push_back(d.ToString());
  return out;
}

struct StrictYamlTest : ::testing::Test {
  std::vector<Diagnostic> problems;
  StrictYaml y{StrictYaml::InFile("f.yaml", {}), &problems};
};

TEST_F(StrictYamlTest, UnknownKeyNamesTheAllowedOnes) {
  const YAML::Node root = YAML::Load("a: 1\ncolour: red\n");
  EXPECT_TRUE(y.Map(root, "", {"b", "a"}));
  EXPECT_EQ(Lines(problems), std::vector<std::string>{"f.yaml:2:1: colour: unknown key (expected one of: a, b)"});
}

TEST_F(StrictYamlTest, DuplicateKeyAtItsSecondWriting) {
  const YAML::Node root = YAML::Load("adam:\n  lr: 1\n  lr: 2\n");
  EXPECT_TRUE(y.Map(root["adam"], "adam", {"lr"}));
  EXPECT_EQ(Lines(problems), std::vector<std::string>{"f.yaml:3:3: adam.lr: duplicate key"});
}

TEST_F(StrictYamlTest, AnEmptyAllowedSetTakesAnyKey) {
  EXPECT_TRUE(y.Map(YAML::Load("x: 1\ny: 2\n"), "hosts", {}));
  EXPECT_TRUE(problems.empty());
}

TEST_F(StrictYamlTest, NotAMappingAndAnEmptyDocumentNameTheFileOnly) {
  EXPECT_FALSE(y.Map(YAML::Load(""), "", {"a"}));
  EXPECT_FALSE(y.Map(YAML::Load("a: [1, 2]\n")["a"], "a", {}));
  EXPECT_EQ(Lines(problems), (std::vector<std::string>{"f.yaml: (top level): must be a mapping",
                                                       "f.yaml:1:4: a: must be a mapping"}));
}

TEST_F(StrictYamlTest, WrongTypeShowsTheValueAndLeavesTheOutputAlone) {
  const YAML::Node root = YAML::Load("n: many\nm: [1]\nx: 2.5\n");
  int n = 7, m = 7;
  double x = 0;
  EXPECT_FALSE(y.Get(root["n"], "n", &n, "an integer"));
  EXPECT_FALSE(y.Get(root, "m", "m", &m, "an integer"));
  EXPECT_TRUE(y.Get(root, "x", "x", &x, "a number"));
  EXPECT_EQ(n, 7);
  EXPECT_EQ(m, 7);
  EXPECT_EQ(x, 2.5);
  EXPECT_EQ(Lines(problems), (std::vector<std::string>{"f.yaml:1:4: n: must be an integer, got 'many'",
                                                       "f.yaml:2:4: m: must be an integer"}));
}

TEST_F(StrictYamlTest, StringMustBeNonEmpty) {
  const YAML::Node root = YAML::Load("a: ''\nb: ok\n");
  std::string a = "kept", b;
  EXPECT_FALSE(y.String(root["a"], "a", &a));
  EXPECT_TRUE(y.String(root["b"], "b", &b));
  EXPECT_EQ(a, "kept");
  EXPECT_EQ(b, "ok");
  EXPECT_EQ(Lines(problems), std::vector<std::string>{"f.yaml:1:4: a: must be a non-empty string"});
}

TEST_F(StrictYamlTest, RequiredKeyMissingIsAtTheParent) {
  const YAML::Node root = YAML::Load("layers:\n  - {d: 4}\n");
  int d = 0, z = 0;
  EXPECT_TRUE(y.Get(root["layers"][0], "d", "layers[0].d", &d, "an integer", true));
  EXPECT_FALSE(y.Get(root["layers"][0], "z", "layers[0].z", &z, "an integer", true));
  EXPECT_FALSE(y.Get(root, "seed", "seed", &z, "an integer"));  // optional: no problem
  EXPECT_EQ(d, 4);
  EXPECT_EQ(Lines(problems), std::vector<std::string>{"f.yaml:2:5: layers[0].z: required key missing"});
}

TEST_F(StrictYamlTest, OneProblemPerKeyTheFirst) {
  // An unknown key written twice is not also a duplicate; a wrong type hides the value's rules.
  const YAML::Node root = YAML::Load("colour: red\ncolour: blue\nn: x\n");
  y.Map(root, "", {"n"});
  int n = 0;
  if (!y.Get(root["n"], "n", &n, "an integer")) y.Error(root["n"], "n", "must be >= 1");
  y.Error(SourceMark{"elsewhere", 1, 1}, "n", "again");
  EXPECT_EQ(Lines(problems), (std::vector<std::string>{"f.yaml:1:1: colour: unknown key (expected one of: n)",
                                                       "f.yaml:3:4: n: must be an integer, got 'x'"}));
}

TEST(StrictYaml, SetValuesAreAtTheirSet) {
  std::vector<Diagnostic> problems;
  StrictYaml y(StrictYaml::InFile("f.yaml", {{"adam.lr", "adam.lr=-1"}, {"layers[0]", "layers.0={d: x}"}}), &problems);
  const YAML::Node root = YAML::Load("adam: {lr: -1}\nlayers: [{d: x}]\nepochs: 0\n");
  y.Error(root["adam"]["lr"], "adam.lr", "must be > 0");
  y.Error(root["adam"], "adam", "held by a set key");
  y.Error(root["layers"][0]["d"], "layers[0].d", "inside a set key");
  y.Error(root["epochs"], "epochs", "must be > 0");
  EXPECT_EQ(Lines(problems), (std::vector<std::string>{"--set adam.lr=-1: adam.lr: must be > 0",
                                                       "--set adam.lr=-1: adam: held by a set key",
                                                       "--set layers.0={d: x}: layers[0].d: inside a set key",
                                                       "f.yaml:3:9: epochs: must be > 0"}));
  EXPECT_TRUE(problems[0].mark.FromCommandLine());
  EXPECT_FALSE(problems[3].mark.FromCommandLine());
}

// The graph plugs in its own lookup (Graph::MarkOf: the file of its extends: chain).
TEST(StrictYaml, PositionsComeFromThePluggedLookup) {
  std::vector<Diagnostic> problems;
  StrictYaml y([](const std::string& key, const YAML::Node& node) { return SourceMark::Of(key + ".yaml", node); },
               &problems);
  y.Map(YAML::Load("a: 1\nb: 2\n"), "", {"a"});
  EXPECT_EQ(Lines(problems), std::vector<std::string>{"b.yaml:2:1: b: unknown key (expected one of: a)"});
}

}  // namespace
}  // namespace dyad
