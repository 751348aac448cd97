#include "dyad/pvrnn/trainer.hpp"

#include <gtest/gtest.h>

#include "dyad/pvrnn/analytic_dataset.hpp"
#include "dyad/pvrnn/prior_generator.hpp"
#include "dyad/pvrnn/softmax_encoding.hpp"

namespace dyad::pvrnn {
namespace {

// A small model keeps this test fast; the study's shape is trained by the benchmark/CLI.
Model SmallModel(const Dataset& d, uint64_t seed) {
  ModelSpec spec = ModelSpec::MacawBot();
  spec.layers[0].d = 16;
  spec.layers[1].d = 6;
  return Model::Initialize(spec, d.steps(), d.size(), seed);
}

TEST(Trainer, LossDropsOnTheAnalyticSet) {
  const Dataset d = MakeAnalyticDataset();
  auto t = Trainer<float>::Create(SmallModel(d, 1), d, TrainerOptions{}).value();
  const double first = t->Epoch().loss;
  LossTerms last;
  for (int e = 0; e < 400; ++e) last = t->Epoch();
  EXPECT_LT(last.loss, 0.5 * first) << "first " << first << " last " << last.loss;
  EXPECT_EQ(t->epoch(), 401);
}

TEST(Trainer, SameSeedSameResult) {
  const Dataset d = MakeAnalyticDataset();
  TrainerOptions o;
  o.seed = 5;
  auto a = Trainer<float>::Create(SmallModel(d, 2), d, o).value();
  auto b = Trainer<float>::Create(SmallModel(d, 2), d, o).value();
  for (int e = 0; e < 20; ++e) {
    a->Epoch();
    b->Epoch();
  }
  EXPECT_EQ(a->Snapshot(false).weights.flat(), b->Snapshot(false).weights.flat());
}

// A checkpoint resumes exactly: 10 + 10 epochs equal 20 uninterrupted ones.
TEST(Trainer, ResumingFromASnapshotContinuesExactly) {
  const Dataset d = MakeAnalyticDataset();
  auto straight = Trainer<double>::Create(SmallModel(d, 3), d, TrainerOptions{}).value();
  auto first = Trainer<double>::Create(SmallModel(d, 3), d, TrainerOptions{}).value();
  for (int e = 0; e < 20; ++e) straight->Epoch();
  for (int e = 0; e < 10; ++e) first->Epoch();
  TrainerOptions other;
  other.seed = 999;  // ignored on resume: the checkpoint carries the RNG
  auto resumed = Trainer<double>::Create(first->Snapshot(true), d, other).value();
  for (int e = 0; e < 10; ++e) resumed->Epoch();
  EXPECT_EQ(resumed->epoch(), 20);
  EXPECT_EQ(resumed->Snapshot(false).weights.flat(), straight->Snapshot(false).weights.flat());
}

TEST(Trainer, RejectsADataSetOfAnotherShape) {
  const Dataset d = MakeAnalyticDataset();
  Model m = SmallModel(d, 1);
  Dataset shorter = d;
  shorter.sequences.pop_back();
  auto t = Trainer<float>::Create(m, shorter, TrainerOptions{});
  ASSERT_FALSE(t.ok());
  EXPECT_NE(t.status().message().find("6 sequences x 72 steps, the model's A has 7 x 72"), std::string::npos)
      << t.status().message();
}

// A position far outside its DOF's range would make the softmax target 0 and the loss NaN.
TEST(Trainer, RejectsAPositionFarOutsideTheEncodingRange) {
  Dataset d = MakeAnalyticDataset();
  const Model m = SmallModel(d, 1);
  d.sequences[2](1, 5) = 51.4;  // NRL's data overshoot a little: accepted
  EXPECT_TRUE(Trainer<float>::Create(m, d, TrainerOptions{}).ok());
  d.sequences[2](1, 5) = 300;
  auto t = Trainer<float>::Create(m, d, TrainerOptions{});
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.status().message(),
            "dataset analytic: primitive 2, step 5 (row 6), DOF 1 = 300: outside the encoding range [-50, 50] by more "
            "than half its width");
}

// RE_P is the reconstruction error of generating every primitive from the prior (first 3 steps
// on its A), summed: the same as GenerateCodes primitive by primitive.
TEST(Trainer, PriorReconstructionIsTheErrorOfPriorGeneration) {
  const Dataset d = MakeAnalyticDataset();
  const Model m = SmallModel(d, 4);
  auto t = Trainer<double>::Create(m, d, TrainerOptions{}).value();
  double expected = 0;
  for (int p = 0; p < d.size(); ++p) {
    const Eigen::MatrixXd x = GenerateCodes(m.weights, m.adaptive, {p}, d.steps(), GenerateOptions{});
    const Eigen::MatrixXd y = EncodePositions(m.spec.output, d.sequences[p]);
    expected += (y.array() * (y.array().log() - x.array().log())).sum();
  }
  EXPECT_NEAR(t->PriorReconstruction(false, 1), expected, 1e-9 * expected);
}

TEST(AdamOptions, DefaultsAreValid) { EXPECT_TRUE(AdamOptions{}.Validate().ok()); }

TEST(AdamOptions, NamesTheBrokenField) {
  AdamOptions o;
  o.beta2 = 1.0;
  EXPECT_EQ(o.Validate().message(), "adam.beta2: must be in [0, 1), got 1");
}

}  // namespace
}  // namespace dyad::pvrnn
