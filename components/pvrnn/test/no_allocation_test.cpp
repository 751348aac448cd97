// The hot loops promise no heap allocation: Trainer::Epoch (training), PriorGenerator::Step
// (generation), WindowObjective::Evaluate and ErrorRegression::Step with Adam (online error
// regression, issue 4). This binary
// replaces the global operator new to count allocations while one of them runs.
#include <gtest/gtest.h>

#include "dyad/testing/allocation_counter.hpp"

#include <cstdlib>

#include "dyad/pvrnn/analytic_dataset.hpp"
#include "dyad/pvrnn/error_regression.hpp"
#include "dyad/pvrnn/prior_generator.hpp"
#include "dyad/pvrnn/trainer.hpp"
#include "dyad/pvrnn/window_objective.hpp"

namespace dyad::pvrnn {
namespace {

using dyad::testing::CountAllocations;

// The counter is live in this binary (otherwise every "allocates nothing" below passes vacuously).
std::vector<double>* volatile g_escape = nullptr;
TEST(NoAllocation, CounterSeesAnAllocation) {
  EXPECT_GE(CountAllocations([] { g_escape = new std::vector<double>(100); }), 2);
  delete g_escape;
}

// With one thread and with the pool's worker (its thread and buffers exist before the first
// epoch; the counter sees allocations on every thread).
TEST(NoAllocation, TrainingEpochAllocatesNothing) {
  const Dataset d = MakeAnalyticDataset();
  for (int threads : {1, 2}) {
    TrainerOptions o;
    o.threads = threads;
    auto t = Trainer<float>::Create(Model::Initialize(ModelSpec::MacawBot(), d.steps(), d.size(), 1), d, o).value();
    ASSERT_EQ(t->threads(), threads);
    t->Epoch();
    EXPECT_EQ(CountAllocations([&] { for (int e = 0; e < 3; ++e) t->Epoch(); }), 0) << threads << " threads";
  }
}

TEST(NoAllocation, PriorGeneratorStepAllocatesNothing) {
  const Model m = Model::Initialize(ModelSpec::MacawBot(), 4, 2, 1);
  PriorGenerator<float> g(m.weights.Cast<float>(), 2);
  const MatrixT<float> a = MatrixT<float>::Zero(m.adaptive.total_z(), 2);
  const MatrixT<float> eps = MatrixT<float>::Zero(m.adaptive.total_z(), 2);
  g.Step(&a, &a, eps);
  EXPECT_EQ(CountAllocations([&] {
              g.Step(&a, &a, eps);
              g.Step(nullptr, nullptr, eps);
            }),
            0);
}

TEST(NoAllocation, WindowObjectiveEvaluateAllocatesNothing) {
  const Model m = Model::Initialize(ModelSpec::MacawBot(), 4, 2, 1);
  const Weights<float> w = m.weights.Cast<float>();
  const int window = 15, tz = m.adaptive.total_z();
  WindowObjective<float> f(w, window);
  f.SetWindow(MatrixT<float>::Constant(w.layout().output_units(), window, 0.1f),
              NetworkState<float>::Zero(w.layout().total_d(), 1), MatrixT<float>::Zero(tz, window), {1e-4, 1e-4});
  AdaptiveVariables<float> a(tz, window, 1), g(tz, window, 1);
  f.Evaluate(a, &g);
  EXPECT_EQ(CountAllocations([&] { f.Evaluate(a, &g); }), 0);
}

// The deliberation step with Adam: nothing allocated once every window size has been seen.
TEST(NoAllocation, ErrorRegressionStepWithAdamAllocatesNothing) {
  for (auto noise : {NoiseMode::kOff, NoiseMode::kFixed, NoiseMode::kResample})
    for (auto init : {AInit::kZero, AInit::kCopy, AInit::kPrior}) {
      ErrorRegressionOptions o = ErrorRegressionOptions::Reference();
      o.noise = noise;
      o.a_init = init;
      auto er = ErrorRegression<float>::Create(Model::Initialize(ModelSpec::MacawBot(), 72, 7, 1), o).value();
      ASSERT_TRUE(er->Reset(1, 1).ok());
      const double xy[2] = {1, 2};
      for (int t = 0; t < o.window + 1; ++t) er->Step(xy);
      EXPECT_EQ(CountAllocations([&] { for (int t = 0; t < 5; ++t) er->Step(xy); }), 0)
          << ToString(noise) << "/" << ToString(init);
    }
}

}  // namespace
}  // namespace dyad::pvrnn
