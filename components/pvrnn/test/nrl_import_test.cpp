// Import of the study's trained MacawBot (NRL text files) and what it draws.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "dyad/pvrnn/nrl_import.hpp"
#include "dyad/pvrnn/posterior_pass.hpp"
#include "dyad/pvrnn/prior_generator.hpp"
#include "dyad/pvrnn/softmax_encoding.hpp"
#include "test_paths.hpp"

namespace dyad::pvrnn {
namespace {

using testing::VcbotDir;

NrlImportOptions MacawOptions() {
  return {VcbotDir() + "/model/MacawBot", VcbotDir() + "/config/properties_MacawBot.d", VcbotDir() + "/dataset/Macaw"};
}

// Root-mean-square distance (workspace units) between a generated and a recorded trajectory.
double Rms(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return std::sqrt((a - b).colwise().squaredNorm().mean());
}

TEST(NrlImport, ReadsTheMacawBotShapes) {
  DYAD_REQUIRE_VCBOT();
  auto model = ImportNrlModel(MacawOptions());
  ASSERT_TRUE(model.ok()) << model.status().message();
  EXPECT_EQ(model->spec, ModelSpec::MacawBot());
  EXPECT_EQ(model->sequences(), 7);
  EXPECT_EQ(model->steps(), 72);
  EXPECT_EQ(model->provenance.epochs, 49300);  // epoch.d: NRL keeps the best model
}

// The study's loss on its own data, evaluated with posterior means. NRL logs loss ~0.42
// (sampled noise, prior from its own trajectory); ours must be of that scale.
TEST(NrlImport, LossOnTheDataSetMatchesTheTrainingLogScale) {
  DYAD_REQUIRE_VCBOT();
  auto model = ImportNrlModel(MacawOptions());
  ASSERT_TRUE(model.ok()) << model.status().message();
  auto data = LoadNrlDataset(VcbotDir() + "/dataset/Macaw");
  ASSERT_TRUE(data.ok());
  const int S = 7, T = 72;
  Eigen::MatrixXd pos(2, S * T);
  for (int t = 0; t < T; ++t)
    for (int s = 0; s < S; ++s) pos.col(t * S + s) = data->sequences[s].col(t);
  const Eigen::MatrixXd targets = EncodePositions(model->spec.output, pos);
  PosteriorPass<double> pass(model->weights.layout(), T, S);
  const Eigen::MatrixXd eps = Eigen::MatrixXd::Zero(5, S * T);
  LossTerms l = pass.Forward(model->weights, model->adaptive, eps, targets, NetworkState<double>::Zero(50, S), {0.01, 0.01});
  std::printf("imported MacawBot, posterior means: RE_Q %.4f  Regulation %.4f  loss %.4f (NRL log: 0.49, 0.87, 0.42)\n",
              l.reconstruction, l.regulation, l.loss);
  EXPECT_LT(l.reconstruction, 2.0);
  EXPECT_LT(l.loss, 1.0);
}

// Prior generation, noise off (means only), first 3 steps on the primitive's trained A.
TEST(NrlImport, ImportedModelDrawsTheMacawFromThePrior) {
  DYAD_REQUIRE_VCBOT();
  auto model = ImportNrlModel(MacawOptions());
  ASSERT_TRUE(model.ok()) << model.status().message();
  auto data = LoadNrlDataset(VcbotDir() + "/dataset/Macaw");
  ASSERT_TRUE(data.ok());
  const char* names[] = {"left eye", "head", "beak", "neck", "right wing", "belly", "left wing"};
  for (int p = 0; p < 7; ++p) {
    const Eigen::MatrixXd xy = GeneratePrimitive(model.value(), p, 72, GenerateOptions{});
    const double rms = Rms(xy, data->sequences[p]);
    std::printf("primitive %d (%s): RMS error %.2f workspace units\n", p, names[p], rms);
    EXPECT_LT(rms, 5.0) << names[p];
  }
}

TEST(NrlImport, MissingFileIsNamed) {
  DYAD_REQUIRE_VCBOT();
  NrlImportOptions o = MacawOptions();
  o.model_dir = testing::TempPath("no_such_model");
  auto model = ImportNrlModel(o);
  ASSERT_FALSE(model.ok());
  EXPECT_NE(model.status().message().find("L0_w_p.d: cannot open"), std::string::npos) << model.status().message();
}

// NRL's Beta network (network=pvrnnbeta) is another model (top-down only, unit Gaussian prior
// and meta-prior w1 at the first step): its properties are refused, naming the file and key.
TEST(NrlImport, RefusesTheBetaNetworkByItsProperties) {
  DYAD_REQUIRE_VCBOT();
  NrlImportOptions o = MacawOptions();
  o.properties_file = testing::TempPath("beta_properties.d");
  {
    std::ifstream in(MacawOptions().properties_file);
    std::ofstream out(o.properties_file);
    for (std::string line; std::getline(in, line);) out << (line == "network=pvrnn" ? "network=pvrnnbeta" : line) << "\n";
  }
  auto model = ImportNrlModel(o);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.status().code(), Status::Code::kUnimplemented);
  EXPECT_NE(model.status().message().find(o.properties_file + ": network=pvrnnbeta"), std::string::npos)
      << model.status().message();
  std::filesystem::remove(o.properties_file);
}

// A Beta model's weights given with a plain properties file: its upper layer has no W_below
// (bottom-up) line. The import must fail and say why, not read the next matrix as W_below.
TEST(NrlImport, BetaWeightFilesAreNamedNotMisread) {
  DYAD_REQUIRE_VCBOT();
  NrlImportOptions o = MacawOptions();
  o.model_dir = testing::TempPath("beta_model");
  std::filesystem::remove_all(o.model_dir);
  std::filesystem::copy(MacawOptions().model_dir, o.model_dir);
  const std::string l1 = o.model_dir + "/L1_w_p.d";
  std::vector<std::string> lines;
  {
    std::ifstream in(l1);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
  }
  ASSERT_EQ(lines.size(), 7u);  // W_dh, W_zh, 4 prior/posterior, W_below (10 x 40)
  {
    std::ofstream out(l1, std::ios::trunc);
    for (size_t i = 0; i < 6; ++i) out << lines[i] << "\n";  // what LayerPvrnnBeta::save writes for the top layer
  }
  auto model = ImportNrlModel(o);
  ASSERT_FALSE(model.ok());
  const std::string& msg = model.status().message();
  EXPECT_NE(msg.find("L1_w_p.d: 6 lines, a layer above the lowest needs 7"), std::string::npos) << msg;
  EXPECT_NE(msg.find("network=pvrnnbeta"), std::string::npos) << msg;
  std::filesystem::remove_all(o.model_dir);
}

}  // namespace
}  // namespace dyad::pvrnn
