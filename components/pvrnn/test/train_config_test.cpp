#include "dyad/pvrnn/train_config.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace dyad::pvrnn {
namespace {

const std::string kDir = DYAD_PVRNN_TEST_DATA_DIR;

TEST(TrainConfig, ValidFileLoads) {
  auto c = LoadTrainConfig(kDir + "/valid_train.yaml");
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->spec, ModelSpec::MacawBot());
  EXPECT_EQ(c->epochs, 100);
  EXPECT_EQ(c->seed, 3u);
  // Every path of a config is relative to the config file.
  EXPECT_EQ(c->dataset, kDir + "/analytic_set");
  EXPECT_EQ(c->output, kDir + "/out.dpvrnn");
  EXPECT_EQ(c->checkpoint, kDir + "/out.dpvrnn.ckpt");
  EXPECT_EQ(c->log_csv, kDir + "/out.dpvrnn.csv");
}

// A path given with --set is relative to the working folder, as a shell user expects.
TEST(TrainConfig, PathsSetOnTheCommandLineAreRelativeToTheWorkingFolder) {
  auto c = LoadTrainConfig(kDir + "/valid_train.yaml", {"dataset=data/set", "output=models/m.dpvrnn"});
  ASSERT_TRUE(c.ok()) << c.status().message();
  const std::string cwd = std::filesystem::current_path().string();
  EXPECT_EQ(c->dataset, cwd + "/data/set");
  EXPECT_EQ(c->output, cwd + "/models/m.dpvrnn");
  EXPECT_EQ(c->checkpoint, cwd + "/models/m.dpvrnn.ckpt");
}

// Golden invalid files: each lists, in `# expect: <suffix>` lines, every message it must give
// (as "<file><suffix>", i.e. file:line:col: key: message, 1-based), all at once and nothing else.
TEST(TrainConfig, EveryInvalidGoldenFileGivesExactlyItsExpectedErrors) {
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kDir + "/invalid")) {
    const std::string path = entry.path().string();
    std::vector<std::string> expected;
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);)
      if (line.rfind("# expect: ", 0) == 0) expected.push_back(path + line.substr(10));
    ASSERT_FALSE(expected.empty()) << path << " has no '# expect:' line";
    auto c = LoadTrainConfig(path);
    ASSERT_FALSE(c.ok()) << path;
    EXPECT_EQ(c.status().code(), Status::Code::kInvalidArgument) << path;
    std::vector<std::string> got;
    std::stringstream ss(c.status().message());
    for (std::string line; std::getline(ss, line);) got.push_back(line);
    std::sort(expected.begin(), expected.end());
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, expected) << path;
    ++files;
  }
  EXPECT_GE(files, 5);
}

// The configs shipped in configs/train load (they are the documentation's examples).
TEST(TrainConfig, ShippedConfigsAreValid) {
  for (const char* name : {"demo.yaml", "macaw.yaml", "macaw_nrl.yaml"}) {
    auto c = LoadTrainConfig(std::string(DYAD_PVRNN_CONFIG_DIR) + "/" + name);
    EXPECT_TRUE(c.ok()) << name << ": " << c.status().message();
  }
}

TEST(TrainConfig, OverridesReplaceValues) {
  auto c = LoadTrainConfig(kDir + "/valid_train.yaml", {"adam.lr=0.005", "layers.1.d=12", "epochs=7"});
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->adam.lr, 0.005);
  EXPECT_EQ(c->spec.layers[1].d, 12);
  EXPECT_EQ(c->epochs, 7);
}

TEST(TrainConfig, LoopsDefaultsToOneAndIsRangeChecked) {
  auto c = LoadTrainConfig(kDir + "/valid_train.yaml");
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->loops, 1);
  auto two = LoadTrainConfig(kDir + "/valid_train.yaml", {"loops=2"});
  ASSERT_TRUE(two.ok()) << two.status().message();
  EXPECT_EQ(two->loops, 2);
  auto zero = LoadTrainConfig(kDir + "/valid_train.yaml", {"loops=0"});
  ASSERT_FALSE(zero.ok());
  EXPECT_EQ(zero.status().message(), "--set loops=0: loops: must be in 1..100, got 0");
}

// prior: nrl (NrlTrainer): NRL's epsilon unless the file sets one; float only.
TEST(TrainConfig, PriorNrlTakesNrlsEpsilonAndFloat) {
  auto c = LoadTrainConfig(kDir + "/valid_train.yaml");
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->prior, "dyad");
  EXPECT_EQ(c->adam.epsilon, 1e-8);
  auto nrl = LoadTrainConfig(kDir + "/valid_train.yaml", {"prior=nrl"});
  ASSERT_TRUE(nrl.ok()) << nrl.status().message();
  EXPECT_EQ(nrl->prior, "nrl");
  EXPECT_EQ(nrl->adam.epsilon, 1e-20);
  auto given = LoadTrainConfig(kDir + "/valid_train.yaml", {"prior=nrl", "adam.epsilon=1e-7"});
  ASSERT_TRUE(given.ok()) << given.status().message();
  EXPECT_EQ(given->adam.epsilon, 1e-7);
  auto dbl = LoadTrainConfig(kDir + "/valid_train.yaml", {"prior=nrl", "scalar=double"});
  ASSERT_FALSE(dbl.ok());
  EXPECT_EQ(dbl.status().message(),
            "--set scalar=double: scalar: must be float with prior: nrl (NRL trains in float), got 'double'");
  auto bad = LoadTrainConfig(kDir + "/valid_train.yaml", {"prior=ceres"});
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message(), "--set prior=ceres: prior: must be dyad or nrl, got 'ceres'");
}

TEST(TrainConfig, ThreadsDefaultToTheCoresAndAreRangeChecked) {
  auto c = LoadTrainConfig(kDir + "/valid_train.yaml");
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->threads, 0);
  auto one = LoadTrainConfig(kDir + "/valid_train.yaml", {"threads=1"});
  ASSERT_TRUE(one.ok()) << one.status().message();
  EXPECT_EQ(one->threads, 1);
  auto bad = LoadTrainConfig(kDir + "/valid_train.yaml", {"threads=-1"});
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().message(), "--set threads=-1: threads: must be in 0..256, got -1");
}

TEST(TrainConfig, BadOverrideIsNamed) {
  auto c = LoadTrainConfig(kDir + "/valid_train.yaml", {"epochs=-3"});
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().message(), "--set epochs=-3: epochs: must be > 0, got -3");
  auto d = LoadTrainConfig(kDir + "/valid_train.yaml", {"adam.momentum=0.5"});
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("--set adam.momentum=0.5: adam.momentum: unknown key"), std::string::npos)
      << d.status().message();
}

// A value rule broken by --set names the --set, not a place in the file.
TEST(TrainConfig, OverrideBreakingASpecRuleIsNamed) {
  auto c = LoadTrainConfig(kDir + "/valid_train.yaml", {"layers.0.d=0", "adam={lr: -1}"});
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().message(),
            "--set layers.0.d=0: layers[0].d: must be in 1..100000, got 0\n"
            "--set adam={lr: -1}: adam.lr: must be finite and > 0, got -1");
}

// --set through a scalar or past a list's end is an error, never an exception.
TEST(TrainConfig, MalformedOverridePathsAreErrors) {
  // (A 23-digit index: std::stoul threw std::out_of_range, out of the loader: dyad train aborted.)
  for (const char* o : {"epochs.x=3", "layers.9.d=1", "layers.x.d=1", "=1", "epochs", "adam=[1", "layers.99999999999999999999999.d=1"}) {
    auto c = LoadTrainConfig(kDir + "/valid_train.yaml", {o});
    ASSERT_FALSE(c.ok()) << o;
    EXPECT_EQ(c.status().message().rfind("--set ", 0), 0u) << o << ": " << c.status().message();
  }
}

TEST(TrainConfig, MissingFileIsNotFound) {
  auto c = LoadTrainConfig(kDir + "/nope.yaml");
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().message(), kDir + "/nope.yaml: cannot open");
}

}  // namespace
}  // namespace dyad::pvrnn
