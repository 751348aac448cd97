// Online error regression (issue 4): options, window bookkeeping, both optimisers lowering the
// window loss on a trajectory pushed away from a primitive, time caps, determinism.
#include "dyad/pvrnn/error_regression.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "dyad/pvrnn/prior_generator.hpp"

namespace dyad::pvrnn {
namespace {

// A random MacawBot-shaped model (no data needed).
Model RandomModel() { return Model::Initialize(ModelSpec::MacawBot(), 72, 7, 5); }

TEST(ErrorRegressionOptions, DefaultsAndPresetsAreValid) {
  EXPECT_TRUE(ErrorRegressionOptions{}.Validate(2).ok());
  EXPECT_TRUE(ErrorRegressionOptions::Vcbot().Validate(2).ok());
  EXPECT_TRUE(ErrorRegressionOptions::Reference().Validate(2).ok());
  EXPECT_TRUE(CeresOptions{}.Validate().ok());
}

TEST(ErrorRegressionOptions, PresetsHoldTheStudySettings) {
  const auto v = ErrorRegressionOptions::Preset("vcbot");
  ASSERT_TRUE(v.has_value());
  EXPECT_EQ(v->window, 5);
  EXPECT_EQ(v->iterations, 15);
  EXPECT_DOUBLE_EQ(v->adam.lr, 0.3);
  EXPECT_DOUBLE_EQ(v->adam.beta1, 0.1);
  EXPECT_DOUBLE_EQ(v->adam.beta2, 0.95);
  EXPECT_EQ(v->meta_prior, (std::vector<double>{1e-5, 1e-5}));
  const auto r = ErrorRegressionOptions::Preset("reference");
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->window, 15);
  EXPECT_EQ(r->iterations, 15);
  EXPECT_DOUBLE_EQ(r->adam.lr, 0.1);
  EXPECT_FALSE(ErrorRegressionOptions::Preset("fast").has_value());
}

TEST(ErrorRegressionOptions, ProblemsNameTheFieldAndValue) {
  ErrorRegressionOptions o;
  o.window = 0;
  o.meta_prior = {1e-5};
  o.adam.lr = -1;
  o.ceres.lbfgs_rank = 0;
  const auto p = o.Problems(2);
  ASSERT_EQ(p.size(), 4u);
  EXPECT_EQ(p[0].ToString(), "window: must be in 1..1000, got 0");
  EXPECT_EQ(p[1].ToString(), "meta_prior: needs one value per layer (2), got 1");
  EXPECT_EQ(p[2].field, "adam.lr");
  EXPECT_EQ(p[3].field, "ceres.lbfgs_rank");
  EXPECT_EQ(ErrorRegression<float>::Create(RandomModel(), o).status().message(),
            "window: must be in 1..1000, got 0");
}

TEST(ErrorRegressionOptions, SpellingsRoundTrip) {
  for (auto v : {AInit::kZero, AInit::kCopy, AInit::kPrior}) EXPECT_EQ(ParseAInit(ToString(v)), v);
  for (auto v : {NoiseMode::kOff, NoiseMode::kFixed, NoiseMode::kResample}) EXPECT_EQ(ParseNoiseMode(ToString(v)), v);
  for (auto v : {OptimizerKind::kAdam, OptimizerKind::kCeres}) EXPECT_EQ(ParseOptimizerKind(ToString(v)), v);
  EXPECT_FALSE(ParseAInit("random").has_value());
}

TEST(ErrorRegression, ResetRejectsAPrimitiveTheModelDoesNotHave) {
  auto er = ErrorRegression<float>::Create(RandomModel(), {}).value();
  const Status s = er->Reset(7, 1);
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.message(), "start_primitive: must be in 0..6 (the model's primitives), got 7");
}

TEST(ErrorRegression, WindowGrowsToWThenSlides) {
  ErrorRegressionOptions o;
  o.window = 4;
  auto er = ErrorRegression<float>::Create(RandomModel(), o).value();
  ASSERT_TRUE(er->Reset(0, 1).ok());
  const double xy[2] = {3, -4};
  for (int t = 0; t < 7; ++t) {
    const StepResult& r = er->Step(xy);
    EXPECT_EQ(r.step, t);
    EXPECT_EQ(r.window_fill, std::min(t + 1, 4));
  }
}

// The first intention is the primitive's first generated step (posterior on its trained A).
TEST(ErrorRegression, FirstIntentionIsThePrimitivesFirstStep) {
  const Model m = RandomModel();
  auto er = ErrorRegression<double>::Create(m, {}).value();
  ASSERT_TRUE(er->Reset(2, 1).ok());
  const Eigen::MatrixXd prior = GeneratePrimitive(m, 2, 1, GenerateOptions{});
  EXPECT_NEAR(er->intention()[0], prior(0, 0), 1e-9);
  EXPECT_NEAR(er->intention()[1], prior(1, 0), 1e-9);
}

// A trajectory generated from a primitive of a random model, then pushed 15 units away: both
// optimisers lower the window loss from its start point at every step (the best iterate is
// never worse than the start). The size of the drop on a trained model: switching_test.cpp.
void ExpectLossLowered(OptimizerKind kind) {
  const Model m = RandomModel();
  ErrorRegressionOptions o;
  o.optimizer = kind;
  o.window = 8;
  o.a_init = AInit::kPrior;
  auto er = ErrorRegression<double>::Create(m, o).value();
  ASSERT_TRUE(er->Reset(1, 1).ok());
  const Eigen::MatrixXd path = GeneratePrimitive(m, 1, 30, GenerateOptions{});
  double first_sum = 0, best_sum = 0;
  for (int t = 0; t < 30; ++t) {
    const double xy[2] = {path(0, t) + (t >= 10 ? 15.0 : 0.0), path(1, t) - (t >= 10 ? 10.0 : 0.0)};
    const StepResult& r = er->Step(xy);
    EXPECT_LE(r.loss.loss, r.initial_loss) << "step " << t;
    EXPECT_GT(r.evaluations, 1);
    if (t >= 10) {
      first_sum += r.initial_loss;
      best_sum += r.loss.loss;
    }
  }
  EXPECT_LT(best_sum, first_sum) << ToString(kind);
}

TEST(ErrorRegression, AdamLowersTheWindowLossOnAPerturbedPrimitive) { ExpectLossLowered(OptimizerKind::kAdam); }
TEST(ErrorRegression, CeresLowersTheWindowLossOnAPerturbedPrimitive) { ExpectLossLowered(OptimizerKind::kCeres); }

TEST(ErrorRegression, APassedDeadlineStopsAfterOneIteration) {
  for (auto kind : {OptimizerKind::kAdam, OptimizerKind::kCeres}) {
    ErrorRegressionOptions o;
    o.optimizer = kind;
    o.iterations = 50;
    auto er = ErrorRegression<float>::Create(RandomModel(), o).value();
    ASSERT_TRUE(er->Reset(0, 1).ok());
    const double xy[2] = {10, 10};
    er->Step(xy);  // warm up the iteration-time estimate
    const StepResult& r = er->Step(xy, SteadyClock::now());
    EXPECT_TRUE(r.stopped_by_deadline) << ToString(kind);
    EXPECT_LE(r.iterations, 1) << ToString(kind);
    EXPECT_GE(r.evaluations, 1) << ToString(kind);
    EXPECT_TRUE(std::isfinite(er->intention()[0]));
  }
}

TEST(ErrorRegression, SameSeedSameRun) {
  ErrorRegressionOptions o;
  o.noise = NoiseMode::kResample;
  auto a = ErrorRegression<float>::Create(RandomModel(), o).value();
  auto b = ErrorRegression<float>::Create(RandomModel(), o).value();
  ASSERT_TRUE(a->Reset(3, 9).ok());
  ASSERT_TRUE(b->Reset(3, 9).ok());
  for (int t = 0; t < 12; ++t) {
    const double xy[2] = {static_cast<double>(t), -static_cast<double>(t)};
    EXPECT_EQ(a->Step(xy).loss.loss, b->Step(xy).loss.loss);
    EXPECT_EQ(a->intention()[0], b->intention()[0]);
  }
}

TEST(ErrorRegression, EveryAInitAndNoiseModeRuns) {
  for (auto init : {AInit::kZero, AInit::kCopy, AInit::kPrior})
    for (auto noise : {NoiseMode::kOff, NoiseMode::kFixed, NoiseMode::kResample}) {
      ErrorRegressionOptions o;
      o.a_init = init;
      o.noise = noise;
      o.window = 3;
      auto er = ErrorRegression<float>::Create(RandomModel(), o).value();
      ASSERT_TRUE(er->Reset(0, 2).ok());
      for (int t = 0; t < 6; ++t) {
        const double xy[2] = {5.0 * t, 0};
        const StepResult& r = er->Step(xy);
        EXPECT_TRUE(std::isfinite(r.loss.loss)) << ToString(init) << "/" << ToString(noise);
        EXPECT_LE(r.loss.loss, r.initial_loss);
      }
    }
}

// One bad reading (a driver or controller sending NaN or inf) must not poison the latent state:
// the window, the inferred states and every later intention would stay NaN for good.
TEST(ErrorRegression, ANonFiniteExecutedPositionDoesNotPoisonTheRun) {
  for (auto kind : {OptimizerKind::kAdam, OptimizerKind::kCeres}) {
    ErrorRegressionOptions o;
    o.optimizer = kind;
    o.window = 3;
    auto er = ErrorRegression<float>::Create(RandomModel(), o).value();
    ASSERT_TRUE(er->Reset(0, 1).ok());
    for (int t = 0; t < 10; ++t) {
      double xy[2] = {2.0 * t, -1.0 * t};
      if (t == 2) xy[0] = std::nan("");
      if (t == 3) xy[1] = INFINITY;
      const StepResult& r = er->Step(xy);
      EXPECT_TRUE(std::isfinite(r.loss.loss)) << ToString(kind) << " step " << t;
      EXPECT_TRUE(std::isfinite(er->intention()[0]) && std::isfinite(er->intention()[1]))
          << ToString(kind) << " step " << t;
    }
  }
}

}  // namespace
}  // namespace dyad::pvrnn
