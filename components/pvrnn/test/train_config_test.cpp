#include "dyad/pvrnn/train_config.hpp"

#include <gtest/gtest.h>

namespace dyad::pvrnn {
namespace {

const std::string kDir = DYAD_PVRNN_TEST_DATA_DIR;

TEST(TrainConfig, ValidFileLoads) {
  auto c = LoadTrainConfig(kDir + "/valid_train.yaml");
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->spec, ModelSpec::MacawBot());
  EXPECT_EQ(c->epochs, 100);
  EXPECT_EQ(c->seed, 3u);
  EXPECT_EQ(c->dataset, kDir + "/analytic_set");  // relative to the config file
  EXPECT_EQ(c->checkpoint, "out.dpvrnn.ckpt");
  EXPECT_EQ(c->log_csv, "out.dpvrnn.csv");
}

// Every error at once, each with file:line:col (1-based) and the key.
TEST(TrainConfig, InvalidFileReportsEveryErrorWithItsPosition) {
  auto c = LoadTrainConfig(kDir + "/invalid_train.yaml");
  ASSERT_FALSE(c.ok());
  const std::string f = kDir + "/invalid_train.yaml";
  const std::string& m = c.status().message();
  EXPECT_NE(m.find(f + ":4:9: layers[1].d: = -1: must be > 0"), std::string::npos) << m;
  EXPECT_NE(m.find(f + ":4:37: layers[1].colour: unknown key"), std::string::npos) << m;
  EXPECT_NE(m.find(f + ":6:19: adam.betta1: unknown key"), std::string::npos) << m;
  EXPECT_NE(m.find(f + ":7:9: scalar: = half: must be float or double"), std::string::npos) << m;
}

TEST(TrainConfig, OverridesReplaceValues) {
  auto c = LoadTrainConfig(kDir + "/valid_train.yaml", {"adam.lr=0.005", "layers.1.d=12", "epochs=7"});
  ASSERT_TRUE(c.ok()) << c.status().message();
  EXPECT_EQ(c->adam.lr, 0.005);
  EXPECT_EQ(c->spec.layers[1].d, 12);
  EXPECT_EQ(c->epochs, 7);
}

TEST(TrainConfig, BadOverrideIsNamed) {
  auto c = LoadTrainConfig(kDir + "/valid_train.yaml", {"epochs=-3"});
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("--set epochs: = -3: must be > 0"), std::string::npos) << c.status().message();
  auto d = LoadTrainConfig(kDir + "/valid_train.yaml", {"adam.momentum=0.5"});
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find("--set adam.momentum: unknown key"), std::string::npos) << d.status().message();
}

TEST(TrainConfig, MissingFileIsNotFound) {
  auto c = LoadTrainConfig(kDir + "/nope.yaml");
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().message(), kDir + "/nope.yaml: cannot open");
}

}  // namespace
}  // namespace dyad::pvrnn
