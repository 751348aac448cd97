// Training the observer: determinism, separation of human-like traces, and the issue's
// acceptance check (confusion diagonal >= 0.95 on prior-generated validation data).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "dyad/observer/evaluation.hpp"
#include "dyad/observer/training.hpp"
#include "dyad/pvrnn/analytic_dataset.hpp"
#include "dyad/pvrnn/nrl_import.hpp"

namespace dyad::observer {
namespace {

std::string Vcbot() { return std::string(DYAD_SHARED_DATA_DIR) + "/vcbot"; }

ClassifierSpec SpecFor(const pvrnn::Dataset& d) {
  ClassifierSpec s;
  s.classes = d.size();
  return s;
}

TEST(TrainClassifier, IsDeterministicPerSeed) {
  const auto data = pvrnn::MakeAnalyticDataset();
  const auto traces = DatasetTraces(data, 1, 0.5, 3);
  ClassifierSpec s = SpecFor(data);
  s.hidden = {12, 8};
  TrainOptions o;
  o.epochs = 3;
  auto a = TrainClassifier(s, traces, o, nullptr), b = TrainClassifier(s, traces, o, nullptr);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->parameters(), b->parameters());
  o.seed = 2;
  EXPECT_NE(TrainClassifier(s, traces, o, nullptr)->parameters(), a->parameters());
}

TEST(TrainClassifier, SeparatesNoisyTracesOfTheAnalyticShapes) {
  const auto data = pvrnn::MakeAnalyticDataset();
  TrainOptions o;
  o.epochs = 100;
  auto c = TrainClassifier(SpecFor(data), DatasetTraces(data, 8, 1.0, 1), o, nullptr);
  ASSERT_TRUE(c.ok()) << c.status().message();
  auto cm = EvaluateTrajectories(c.value(), DatasetTraces(data, 2, 1.0, 99));
  ASSERT_TRUE(cm.ok());
  std::printf("%sdiagonal min %.4f\n", cm->ToTable().c_str(), cm->MinDiagonal());
  EXPECT_GE(cm->MinDiagonal(), 0.9);
}

TEST(TrainClassifier, RejectsBadOptionsAndData) {
  const auto data = pvrnn::MakeAnalyticDataset();
  TrainOptions o;
  o.epochs = 0;
  EXPECT_EQ(TrainClassifier(SpecFor(data), DatasetTraces(data, 1, 0, 1), o, nullptr).status().message(),
            "epochs: must be >= 1, got 0");
  std::vector<LabelledTrajectory> bad = DatasetTraces(data, 1, 0, 1);
  bad[2].primitive = 7;
  EXPECT_EQ(EvaluateTrajectories(Classifier::Create(SpecFor(data), 1).value(), bad).status().message(),
            "trajectory 2: primitive 7 outside 0..6");
  PriorDataOptions p;
  p.steps = 20;
  EXPECT_FALSE(GeneratePriorTrajectories(pvrnn::Model{}, p).ok());
}

// The acceptance check of issue 5 with the study's own model: train on prior generations with
// seeds 1..5, validate on seeds 101..103 (200 steps each, first 20 dropped).
TEST(TrainObserver, MacawBotConfusionDiagonalAtLeast095OnPriorValidationData) {
  if (!std::filesystem::exists(Vcbot() + "/model/MacawBot"))
    GTEST_SKIP() << "needs ../shared/data/vcbot (not found at " << Vcbot() << ")";
  auto model = pvrnn::ImportNrlModel(
      {Vcbot() + "/model/MacawBot", Vcbot() + "/config/properties_MacawBot.d", Vcbot() + "/dataset/Macaw"});
  ASSERT_TRUE(model.ok()) << model.status().message();
  PriorDataOptions data;
  auto train = GeneratePriorTrajectories(model.value(), data);
  data.seeds = {101, 102, 103};
  auto validation = GeneratePriorTrajectories(model.value(), data);
  ASSERT_TRUE(train.ok() && validation.ok());
  TrainOptions o;
  o.epochs = 50;
  auto c = TrainClassifier(ClassifierSpecFor(model.value()), train.value(), o, nullptr);
  ASSERT_TRUE(c.ok()) << c.status().message();
  auto cm = EvaluateTrajectories(c.value(), validation.value());
  ASSERT_TRUE(cm.ok());
  std::printf("MacawBot, prior validation seeds 101..103:\n%sdiagonal min %.4f accuracy %.4f\n", cm->ToTable().c_str(),
              cm->MinDiagonal(), cm->Accuracy());
  EXPECT_GE(cm->MinDiagonal(), 0.95);
  // And on the data set itself traced like a human with 1 unit of noise.
  auto data_set = pvrnn::LoadNrlDataset(Vcbot() + "/dataset/Macaw");
  ASSERT_TRUE(data_set.ok());
  auto human = EvaluateTrajectories(c.value(), DatasetTraces(data_set.value(), 2, 1.0, 1));
  std::printf("Macaw data set traced twice, noise 1: diagonal min %.4f accuracy %.4f\n", human->MinDiagonal(),
              human->Accuracy());
  EXPECT_GE(human->Accuracy(), 0.95);
}

}  // namespace
}  // namespace dyad::observer
