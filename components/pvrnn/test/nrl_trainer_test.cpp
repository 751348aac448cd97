// dyad's NRL mode for training (`prior: nrl`, NrlTrainer) against NRL itself (issue 44, item 2):
// on the committed trace of NRL's training (test/data/nrl/nrl_train.csv, made by
// bench/pvrnn/nrl_reference.sh from oist-cnru/NRL 42395a2, -O3, noise set to 0: the study's
// MacawBot properties on the Macaw data set from NRL's initial state, 200 epochs), dyad's NRL
// mode from NRL's initial state (replayed: glibc's rand() under Eigen's MatrixXf::Random in NRL's
// construction order) with noise off must give every epoch's loss, reconstruction and regulation
// within 1e-4 relative inside NRL's own reproducibility horizon: NRL's builds (CMake defaults,
// -O3, -O3 -march=native) agree within 1e-4 relative through epoch 52 (first beyond at 53-54;
// docs/pvrnn.md). The largest deviation per quantity is printed (the note quotes it).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "dyad/pvrnn/nrl_trainer.hpp"
#include "dyad/pvrnn/train_config.hpp"
#include "dyad/pvrnn/trainer.hpp"
#include "test_paths.hpp"

namespace dyad::pvrnn {
namespace {

constexpr int kHorizon = 52;  // epochs 1..52: NRL's builds agree within 1e-4 relative

struct EpochRow {
  double loss = 0, reconstruction = 0, regulation = 0;
};

std::vector<EpochRow> ReadTrainTrace(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::vector<EpochRow> rows;
  std::string line;
  std::getline(in, line);  // header: epoch,loss,reconstruction,regulation
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    EXPECT_EQ(cells.size(), 4u) << path << ": " << line;
    EXPECT_EQ(std::stoi(cells.at(0)), static_cast<int>(rows.size()) + 1) << path;
    rows.push_back({std::stod(cells.at(1)), std::stod(cells.at(2)), std::stod(cells.at(3))});
  }
  return rows;
}

double Relative(double got, double want) { return std::abs(got - want) / std::max(std::abs(want), 1e-30); }

class NrlTraining : public ::testing::Test {
 protected:
  void SetUp() override {
    DYAD_REQUIRE_VCBOT();
    auto c = LoadTrainConfig(std::string(DYAD_PVRNN_CONFIG_DIR) + "/macaw.yaml");  // MacawBot's shape
    ASSERT_TRUE(c.ok()) << c.status().message();
    spec_ = c->spec;
    auto d = LoadNrlDataset(testing::VcbotDir() + "/dataset/Macaw");
    ASSERT_TRUE(d.ok()) << d.status().message();
    data_ = d.value();
    trace_ = ReadTrainTrace(std::string(DYAD_PVRNN_TEST_DATA_DIR) + "/nrl/nrl_train.csv");
    ASSERT_GE(static_cast<int>(trace_.size()), kHorizon);
  }
  ModelSpec spec_;
  Dataset data_;
  std::vector<EpochRow> trace_;
};

TEST_F(NrlTraining, ReproducesNrlsLossPerEpochInsideItsHorizon) {
  const Model start = NrlTrainer::InitialModel(spec_, data_.steps(), data_.size());
  auto made = NrlTrainer::Create(start, data_, {});  // NRL's Adam (0.001, 0.9, 0.999, 1e-20), noise 0
  ASSERT_TRUE(made.ok()) << made.status().message();
  NrlTrainer& trainer = *made.value();
  double loss = 0, rec = 0, reg = 0;
  for (int e = 1; e <= kHorizon; ++e) {
    const LossTerms& l = trainer.Epoch();
    const EpochRow& want = trace_[e - 1];
    loss = std::max(loss, Relative(l.loss, want.loss));
    rec = std::max(rec, Relative(l.reconstruction, want.reconstruction));
    reg = std::max(reg, Relative(l.regulation, want.regulation));
    EXPECT_LT(Relative(l.loss, want.loss), 1e-4) << "epoch " << e << ": " << l.loss << " vs NRL " << want.loss;
    EXPECT_LT(Relative(l.reconstruction, want.reconstruction), 1e-4) << "epoch " << e;
    EXPECT_LT(Relative(l.regulation, want.regulation), 1e-4) << "epoch " << e;
  }
  EXPECT_EQ(trainer.epoch(), kHorizon);
  std::printf(
      "NRL mode vs NRL (nrl_train.csv), epochs 1..%d: largest deviation: loss %.3g, reconstruction %.3g, "
      "regulation %.3g (relative)\n",
      kHorizon, loss, rec, reg);
}

// With NRL's published noise (N(0,1) for prior and posterior in every pass, libstdc++'s
// normal_distribution<float> over default_random_engine seeded 0: nrl_train_noise.csv, NRL -O3),
// the mode with noise on and seed 0 draws NRL's very numbers. Noisy training does not amplify
// rounding as the noiseless one does: NRL's three builds agree within 7e-6 relative over all 200
// epochs (docs/pvrnn.md); the test holds the first 100 (to stay fast under the sanitizers).
TEST_F(NrlTraining, ReproducesNrlsNoisyTrainingWithTheSameStandardLibrary) {
#ifndef __GLIBCXX__
  GTEST_SKIP() << "NRL's draws are libstdc++'s";
#endif
  constexpr int kEpochs = 100;
  const std::vector<EpochRow> trace = ReadTrainTrace(std::string(DYAD_PVRNN_TEST_DATA_DIR) + "/nrl/nrl_train_noise.csv");
  ASSERT_GE(static_cast<int>(trace.size()), kEpochs);
  NrlTrainerOptions o;
  o.noise = true;
  o.seed = 0;  // NRL's
  auto made = NrlTrainer::Create(NrlTrainer::InitialModel(spec_, data_.steps(), data_.size()), data_, o);
  ASSERT_TRUE(made.ok()) << made.status().message();
  double worst = 0;
  for (int e = 1; e <= kEpochs; ++e) {
    const LossTerms& l = made.value()->Epoch();
    const EpochRow& want = trace[e - 1];
    const double r = std::max(
        {Relative(l.loss, want.loss), Relative(l.reconstruction, want.reconstruction), Relative(l.regulation, want.regulation)});
    worst = std::max(worst, r);
    EXPECT_LT(r, 1e-4) << "epoch " << e << ": loss " << l.loss << " vs NRL " << want.loss;
  }
  std::printf("NRL mode with NRL's noise vs NRL (nrl_train_noise.csv), epochs 1..%d: largest deviation %.3g (relative)\n",
              kEpochs, worst);
}

// dyad's own trainer (exact gradient, its own initialisation) from the same start misses NRL's
// losses: the mode is needed.
TEST_F(NrlTraining, DyadsTrainerDoesNotReproduceNrl) {
  const Model start = NrlTrainer::InitialModel(spec_, data_.steps(), data_.size());
  TrainerOptions o;
  o.adam = {0.001, 0.9, 0.999, 1e-20};
  o.sample_noise = false;
  auto made = Trainer<float>::Create(start, data_, o);
  ASSERT_TRUE(made.ok()) << made.status().message();
  double worst = 0;
  for (int e = 1; e <= kHorizon; ++e) worst = std::max(worst, Relative(made.value()->Epoch().loss, trace_[e - 1].loss));
  std::printf("dyad's trainer from NRL's initial state vs NRL, epochs 1..%d: loss %.3g relative\n", kHorizon, worst);
  EXPECT_GT(worst, 1e-2);
}

TEST_F(NrlTraining, RefusesSeveralSamplesOfAPrimitive) {
  Dataset two = data_;
  two.primitive.clear(), two.sample.clear();
  for (int k = 0; k < two.size(); ++k) two.primitive.push_back(k / 2), two.sample.push_back(k % 2);
  auto made = NrlTrainer::Create(NrlTrainer::InitialModel(spec_, two.steps(), two.size()), two, {});
  ASSERT_FALSE(made.ok());
  EXPECT_NE(made.status().message().find("one sample per primitive"), std::string::npos) << made.status().message();
}

}  // namespace
}  // namespace dyad::pvrnn
